// Bounds-checked little-endian writing and reading of one message in a
// buffer, for the protocols' codecs (the flash protocol's FlashMessage, the
// configuration protocol's SeiMessage). A writer past the end keeps
// counting but writes nothing, and finish() then says 0; a reader past the
// end reads zeros, and exact() then says false. So a codec writes and reads
// its fields in order and asks once, at the end, whether they fitted.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace runtime {

class ByteWriter {
public:
    ByteWriter(uint8_t* out, size_t capacity) : out_(out), capacity_(out != nullptr ? capacity : 0) {}

    void u8(uint8_t value)
    {
        if (at_ < capacity_) {
            out_[at_] = value;
        }
        ++at_;
    }
    void u16(uint16_t value)
    {
        u8(static_cast<uint8_t>(value));
        u8(static_cast<uint8_t>(value >> 8));
    }
    void u32(uint32_t value)
    {
        u16(static_cast<uint16_t>(value));
        u16(static_cast<uint16_t>(value >> 16));
    }
    /// @p count bytes from @p data, or zeros when @p data is null.
    void bytes(const uint8_t* data, size_t count)
    {
        for (size_t i = 0; i < count; ++i) {
            u8(data != nullptr ? data[i] : 0);
        }
    }
    /// The length written, or 0 when it did not fit.
    size_t finish() const { return at_ <= capacity_ ? at_ : 0; }

private:
    uint8_t* out_;
    size_t capacity_;
    size_t at_ = 0;
};

class ByteReader {
public:
    ByteReader(const uint8_t* data, size_t length) : data_(data), length_(length) {}

    uint8_t u8() { return at_ < length_ ? data_[at_++] : (++at_, 0); }
    uint16_t u16()
    {
        const uint16_t low = u8();
        return static_cast<uint16_t>(low | (u8() << 8));
    }
    uint32_t u32()
    {
        const uint32_t low = u16();
        return low | (static_cast<uint32_t>(u16()) << 16);
    }
    void bytes(uint8_t* out, size_t count)
    {
        for (size_t i = 0; i < count; ++i) {
            out[i] = u8();
        }
    }
    /// @p count bytes in place: where they start, or null when they are not all there.
    const uint8_t* take(size_t count)
    {
        const uint8_t* start = at_ <= length_ && count <= length_ - at_ ? data_ + at_ : nullptr;
        at_ += count;
        return start;
    }
    /// Where the next byte is, or null past the end.
    const uint8_t* here() const { return at_ <= length_ ? data_ + at_ : nullptr; }
    void skip(size_t count) { at_ += count; }
    /// Every byte read, and none missing.
    bool exact() const { return at_ == length_; }

private:
    const uint8_t* data_;
    size_t length_;
    size_t at_ = 0;
};

} // namespace runtime
