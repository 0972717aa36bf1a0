// A small printf-style formatter for firmware that has no C library.
//
// Output goes to a CharacterSink, so the same code formats onto the console,
// into a fixed buffer, or into a test's string. Supported conversions are
// the ones diagnostic code needs: %d %i %u %x %X %o %c %s %p and %%, with the
// flags '-' (left-justify), '0' (zero padding), a decimal field width (or
// '*'), a precision for strings (maximum length, or '.*'), and the length
// modifiers 'l' and 'll' (64-bit). No floating point: the kernel is built
// without FPU use, and a control engineer formats engineering values with
// explicit fixed-point helpers instead.
#pragma once

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

namespace runtime {

/// Receives formatted characters one at a time.
class CharacterSink {
public:
    /// Appends one character to the output.
    virtual void put(char character) = 0;

protected:
    ~CharacterSink() = default;
};

/// A sink that writes into a caller's fixed buffer and always terminates it.
///
/// Characters beyond the buffer are counted but dropped, exactly like
/// snprintf, so a caller can see that its output was truncated.
class BufferSink final : public CharacterSink {
public:
    /// Wraps a buffer of capacity bytes; capacity may be zero.
    BufferSink(char* buffer, size_t capacity);

    void put(char character) override;

    /// Characters offered so far, including any that did not fit.
    size_t length() const { return length_; }

    /// True when some characters did not fit.
    bool truncated() const { return capacity_ != 0 ? length_ >= capacity_ : length_ != 0; }

private:
    char* buffer_;
    size_t capacity_;
    size_t length_ = 0;
};

/// Formats according to a printf-style format into sink. Returns the number
/// of characters produced. An unknown conversion is copied through literally
/// so that a bad format string is visible rather than silently lost.
size_t formatTo(CharacterSink& sink, const char* format, va_list arguments);

/// Variadic convenience wrapper around formatTo().
size_t format(CharacterSink& sink, const char* format, ...) __attribute__((format(printf, 2, 3)));

/// snprintf equivalent: formats into buffer (always terminated when capacity
/// is non-zero) and returns the full length the output would have had.
size_t formatToBuffer(char* buffer, size_t capacity, const char* format, ...)
    __attribute__((format(printf, 3, 4)));

} // namespace runtime
