#include <can/FrameText.hpp>

namespace can {

namespace {

// The longest text parse() takes: an extended identifier, '#' and 8 bytes
// with a dot after each but the last.
constexpr size_t kMaxParsedLength = 8 + 1 + 8 * 2 + 7;

int hexValue(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

constexpr char kDigits[] = "0123456789ABCDEF";

} // namespace

LinkResult<CanFrame> FrameText::parse(const char* text)
{
    if (text == nullptr) {
        return LinkError::InvalidHexDigit;
    }
    size_t length = 0;
    while (text[length] != '\0') {
        if (++length > kMaxParsedLength) {
            return LinkError::LineTooLong;
        }
    }
    size_t idDigits = 0;
    uint32_t id = 0;
    for (; text[idDigits] != '#'; ++idDigits) {
        const int digit = hexValue(text[idDigits]);
        if (digit < 0) {
            return LinkError::InvalidHexDigit; // Also the NUL of text without a '#'.
        }
        if (idDigits == 8) {
            return LinkError::InvalidIdentifier;
        }
        id = (id << 4) | static_cast<uint32_t>(digit);
    }
    if (idDigits != 3 && idDigits != 8) {
        return LinkError::InvalidIdentifier;
    }
    const IdFormat format = idDigits == 8 ? IdFormat::Extended : IdFormat::Standard;
    const char* p = text + idDigits + 1;
    if (*p == 'R' || *p == 'r') {
        ++p;
        uint8_t dlc = 0;
        if (*p != '\0') {
            const int digit = hexValue(*p);
            if (digit < 0 || digit > CanFrame::kMaxDataLength || p[1] != '\0') {
                return digit < 0 ? LinkError::InvalidHexDigit : LinkError::InvalidDataLength;
            }
            dlc = static_cast<uint8_t>(digit);
        }
        return CanFrame::makeRemote(id, format, dlc);
    }
    uint8_t data[CanFrame::kMaxDataLength];
    uint8_t count = 0;
    while (*p != '\0') {
        if (*p == '.' && count > 0 && p[1] != '\0' && p[1] != '.') {
            ++p; // A separator between two bytes, as cansend allows.
            continue;
        }
        const int high = hexValue(p[0]);
        if (high < 0) {
            return LinkError::InvalidHexDigit;
        }
        if (p[1] == '\0') {
            return LinkError::InvalidDataLength; // Half a byte.
        }
        const int low = hexValue(p[1]);
        if (low < 0) {
            return LinkError::InvalidHexDigit;
        }
        if (count == CanFrame::kMaxDataLength) {
            return LinkError::InvalidDataLength;
        }
        data[count++] = static_cast<uint8_t>(high << 4 | low);
        p += 2;
    }
    return CanFrame::makeData(id, format, data, count);
}

size_t FrameText::format(const CanFrame& frame, char* buffer, size_t capacity)
{
    char text[kMaxFormattedLength + 16];
    size_t n = 0;
    const unsigned idDigits = frame.isExtended() ? 8 : 3;
    for (unsigned i = 0; i < idDigits; ++i) {
        text[n++] = kDigits[(frame.id() >> (4 * (idDigits - 1 - i))) & 0xF];
    }
    // candump pads a standard identifier to the width of an extended one.
    for (unsigned i = idDigits; i < 8; ++i) {
        text[n++] = ' ';
    }
    text[n++] = ' ';
    text[n++] = ' ';
    text[n++] = ' ';
    text[n++] = '[';
    text[n++] = static_cast<char>('0' + frame.length());
    text[n++] = ']';
    if (frame.isRemote()) {
        for (const char* word = "  remote request"; *word != '\0'; ++word) {
            text[n++] = *word;
        }
    } else {
        text[n++] = ' ';
        for (uint8_t i = 0; i < frame.length(); ++i) {
            text[n++] = ' ';
            text[n++] = kDigits[frame.byte(i) >> 4];
            text[n++] = kDigits[frame.byte(i) & 0xF];
        }
    }
    if (buffer == nullptr || n + 1 > capacity) {
        return 0;
    }
    for (size_t i = 0; i < n; ++i) {
        buffer[i] = text[i];
    }
    buffer[n] = '\0';
    return n;
}

} // namespace can
