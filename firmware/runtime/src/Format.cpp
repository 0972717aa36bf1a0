#include <runtime/Format.hpp>

namespace runtime {

BufferSink::BufferSink(char* buffer, size_t capacity) : buffer_(buffer), capacity_(capacity)
{
    if (capacity_ != 0) {
        buffer_[0] = '\0';
    }
}

void BufferSink::put(char character)
{
    if (length_ + 1 < capacity_) {
        buffer_[length_] = character;
        buffer_[length_ + 1] = '\0';
    }
    ++length_;
}

namespace {

struct Specification {
    bool leftJustify = false;
    bool zeroPad = false;
    unsigned width = 0;
    int precision = -1;
};

class CountingWriter {
public:
    explicit CountingWriter(CharacterSink& sink) : sink_(sink) {}
    void put(char c)
    {
        sink_.put(c);
        ++count_;
    }
    void repeat(char c, unsigned times)
    {
        for (unsigned i = 0; i < times; ++i) {
            put(c);
        }
    }
    size_t count() const { return count_; }

private:
    CharacterSink& sink_;
    size_t count_ = 0;
};

// Emits text of the given length, padded to the field width.
void emitPadded(CountingWriter& out, const Specification& spec, const char* text, unsigned length,
                bool negative)
{
    const unsigned signLength = negative ? 1u : 0u;
    const unsigned total = length + signLength;
    const unsigned padding = spec.width > total ? spec.width - total : 0u;
    if (!spec.leftJustify && !spec.zeroPad) {
        out.repeat(' ', padding);
    }
    if (negative) {
        out.put('-');
    }
    if (!spec.leftJustify && spec.zeroPad) {
        out.repeat('0', padding);
    }
    for (unsigned i = 0; i < length; ++i) {
        out.put(text[i]);
    }
    if (spec.leftJustify) {
        out.repeat(' ', padding);
    }
}

// Converts a value to digits in the given base. Bases are 8, 10 or 16, so
// 32-bit values use the native divide and 64-bit values the runtime's own.
unsigned toDigits(uint64_t value, unsigned base, bool upper, char* digits)
{
    const char* alphabet = upper ? "0123456789ABCDEF" : "0123456789abcdef";
    char reversed[24];
    unsigned length = 0;
    do {
        if ((value >> 32) == 0) {
            uint32_t small = static_cast<uint32_t>(value);
            reversed[length++] = alphabet[small % base];
            value = small / base;
        } else {
            reversed[length++] = alphabet[value % base];
            value /= base;
        }
    } while (value != 0);
    for (unsigned i = 0; i < length; ++i) {
        digits[i] = reversed[length - 1 - i];
    }
    return length;
}

} // namespace

size_t formatTo(CharacterSink& sink, const char* format, va_list arguments)
{
    CountingWriter out(sink);
    for (const char* p = format; *p != '\0'; ++p) {
        if (*p != '%') {
            out.put(*p);
            continue;
        }
        const char* conversionStart = p;
        ++p;
        Specification spec;
        for (;; ++p) {
            if (*p == '-') {
                spec.leftJustify = true;
            } else if (*p == '0') {
                spec.zeroPad = true;
            } else {
                break;
            }
        }
        if (*p == '*') {
            const int width = va_arg(arguments, int);
            if (width < 0) {
                spec.leftJustify = true;
                spec.width = static_cast<unsigned>(-width);
            } else {
                spec.width = static_cast<unsigned>(width);
            }
            ++p;
        } else {
            while (*p >= '0' && *p <= '9') {
                spec.width = spec.width * 10 + static_cast<unsigned>(*p - '0');
                ++p;
            }
        }
        if (*p == '.') {
            ++p;
            if (*p == '*') {
                spec.precision = va_arg(arguments, int);
                ++p;
            } else {
                spec.precision = 0;
                while (*p >= '0' && *p <= '9') {
                    spec.precision = spec.precision * 10 + (*p - '0');
                    ++p;
                }
            }
        }
        unsigned longs = 0;
        while (*p == 'l') {
            ++longs;
            ++p;
        }
        char digits[24];
        switch (*p) {
        case 'd':
        case 'i': {
            const int64_t value = longs >= 2 ? va_arg(arguments, long long)
                                  : longs == 1 ? va_arg(arguments, long)
                                               : va_arg(arguments, int);
            const bool negative = value < 0;
            const uint64_t magnitude = negative ? uint64_t{0} - static_cast<uint64_t>(value)
                                                : static_cast<uint64_t>(value);
            emitPadded(out, spec, digits, toDigits(magnitude, 10, false, digits), negative);
            break;
        }
        case 'u':
        case 'x':
        case 'X':
        case 'o': {
            const uint64_t value = longs >= 2 ? va_arg(arguments, unsigned long long)
                                   : longs == 1 ? va_arg(arguments, unsigned long)
                                                : va_arg(arguments, unsigned int);
            const unsigned base = (*p == 'u') ? 10u : (*p == 'o') ? 8u : 16u;
            emitPadded(out, spec, digits, toDigits(value, base, *p == 'X', digits), false);
            break;
        }
        case 'p': {
            const uintptr_t value = reinterpret_cast<uintptr_t>(va_arg(arguments, void*));
            Specification pointerSpec;
            pointerSpec.zeroPad = true;
            pointerSpec.width = sizeof(uintptr_t) * 2;
            out.put('0');
            out.put('x');
            emitPadded(out, pointerSpec, digits, toDigits(value, 16, false, digits), false);
            break;
        }
        case 'c': {
            const char c = static_cast<char>(va_arg(arguments, int));
            spec.zeroPad = false;
            emitPadded(out, spec, &c, 1, false);
            break;
        }
        case 's': {
            const char* text = va_arg(arguments, const char*);
            if (text == nullptr) {
                text = "(null)";
            }
            unsigned length = 0;
            while (text[length] != '\0' &&
                   (spec.precision < 0 || length < static_cast<unsigned>(spec.precision))) {
                ++length;
            }
            spec.zeroPad = false;
            emitPadded(out, spec, text, length, false);
            break;
        }
        case '%':
            out.put('%');
            break;
        default:
            // Unknown or truncated conversion: show it as written.
            for (const char* q = conversionStart; q <= p && *q != '\0'; ++q) {
                out.put(*q);
            }
            if (*p == '\0') {
                return out.count();
            }
            break;
        }
    }
    return out.count();
}

size_t format(CharacterSink& sink, const char* format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    const size_t count = formatTo(sink, format, arguments);
    va_end(arguments);
    return count;
}

size_t formatToBuffer(char* buffer, size_t capacity, const char* format, ...)
{
    BufferSink sink(buffer, capacity);
    va_list arguments;
    va_start(arguments, format);
    formatTo(sink, format, arguments);
    va_end(arguments);
    return sink.length();
}

} // namespace runtime
