#include <image/ImageVersion.hpp>

namespace image {

namespace {

// Reads a decimal number of at most @p maximum at @p text, moving it past
// the digits; false when there are none or the value is too large.
bool readNumber(const char*& text, uint32_t maximum, uint32_t& out)
{
    if (*text < '0' || *text > '9') {
        return false;
    }
    uint32_t value = 0;
    for (; *text >= '0' && *text <= '9'; ++text) {
        const uint32_t digit = static_cast<uint32_t>(*text - '0');
        if (value > (maximum - digit) / 10) {
            return false;
        }
        value = value * 10 + digit;
    }
    out = value;
    return true;
}

size_t appendNumber(char* out, size_t size, size_t at, uint32_t value)
{
    char digits[10];
    size_t count = 0;
    do {
        digits[count++] = static_cast<char>('0' + value % 10);
        value /= 10;
    } while (value != 0);
    while (count > 0) {
        const char digit = digits[--count];
        if (at + 1 < size) {
            out[at] = digit;
        }
        ++at;
    }
    return at;
}

size_t appendCharacter(char* out, size_t size, size_t at, char character)
{
    if (at + 1 < size) {
        out[at] = character;
    }
    return at + 1;
}

} // namespace

int ImageVersion::compare(const ImageVersion& other) const
{
    if (major != other.major) {
        return major < other.major ? -1 : 1;
    }
    if (minor != other.minor) {
        return minor < other.minor ? -1 : 1;
    }
    if (patch != other.patch) {
        return patch < other.patch ? -1 : 1;
    }
    if (build != other.build) {
        return build < other.build ? -1 : 1;
    }
    return 0;
}

bool ImageVersion::parse(const char* text, ImageVersion& out)
{
    if (text == nullptr) {
        return false;
    }
    uint32_t major = 0;
    uint32_t minor = 0;
    uint32_t patch = 0;
    uint32_t build = 0;
    if (!readNumber(text, 0xFF, major) || *text++ != '.' || !readNumber(text, 0xFF, minor) || *text++ != '.' ||
        !readNumber(text, 0xFFFF, patch)) {
        return false;
    }
    if (*text == '+') {
        ++text;
        if (!readNumber(text, 0xFFFFFFFFu, build)) {
            return false;
        }
    }
    if (*text != '\0') {
        return false;
    }
    out.major = static_cast<uint8_t>(major);
    out.minor = static_cast<uint8_t>(minor);
    out.patch = static_cast<uint16_t>(patch);
    out.build = build;
    return true;
}

size_t ImageVersion::format(char* out, size_t size) const
{
    size_t at = appendNumber(out, size, 0, major);
    at = appendCharacter(out, size, at, '.');
    at = appendNumber(out, size, at, minor);
    at = appendCharacter(out, size, at, '.');
    at = appendNumber(out, size, at, patch);
    if (build != 0) {
        at = appendCharacter(out, size, at, '+');
        at = appendNumber(out, size, at, build);
    }
    if (size > 0) {
        out[at < size ? at : size - 1] = '\0';
    }
    return at;
}

} // namespace image
