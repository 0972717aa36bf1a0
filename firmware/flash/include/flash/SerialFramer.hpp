// The flash protocol's frames on a serial line (docs/protocols/flash.md,
// "On a serial line"): two sync bytes D5 C5, the payload's length
// (16 bits, little-endian, 1 to kMaxMessage), the payload (one
// FlashMessage), and the CRC-32 of the length and the payload
// (little-endian). The receiver is a state machine fed one byte at a time:
// a frame with a bad length or CRC is dropped and the receiver looks for
// the next sync, so line noise, console text and a torn frame cost only
// that frame.
#pragma once

#include <flash/FlashMessage.hpp>

#include <stddef.h>
#include <stdint.h>

namespace flash {

class SerialFramer {
public:
    static constexpr uint8_t kSync0 = 0xD5;
    static constexpr uint8_t kSync1 = 0xC5;
    static constexpr size_t kOverhead = 2 + 2 + 4;

    /// Frames @p length bytes of @p payload into @p out; the frame's length,
    /// or 0 when it does not fit or the payload is empty or too long.
    static size_t frame(const uint8_t* payload, size_t length, uint8_t* out, size_t capacity);

    /// Takes one received byte; true when it completed a valid frame, whose
    /// payload is then payload()/payloadLength() until the next byte.
    bool receive(uint8_t byte);

    /// Abandons a frame begun but not finished (counted as dropped): the
    /// receiver's owner calls it when the line has been silent too long,
    /// so that a sender that died mid-frame does not swallow the next one.
    void reset();
    /// True while a frame is begun but not finished.
    bool inFrame() const { return state_ != State::Sync0; }

    const uint8_t* payload() const { return buffer_; }
    size_t payloadLength() const { return length_; }
    /// Frames dropped for a bad length or CRC since construction.
    uint32_t dropped() const { return dropped_; }

private:
    enum class State : uint8_t { Sync0, Sync1, Length0, Length1, Payload, Crc };

    State state_ = State::Sync0;
    uint8_t buffer_[kMaxMessage] = {};
    size_t length_ = 0;
    size_t at_ = 0;
    uint8_t crcBytes_[4] = {};
    uint32_t dropped_ = 0;
};

} // namespace flash
