#include <flash/SerialFramer.hpp>

#include <boot/Crc32.hpp>

namespace flash {

namespace {

uint32_t frameCrc(const uint8_t* payload, size_t length)
{
    // The CRC covers the length bytes and the payload: a corrupted length
    // that still lands on a plausible size is caught too.
    uint8_t scratch[2 + kMaxMessage];
    scratch[0] = static_cast<uint8_t>(length);
    scratch[1] = static_cast<uint8_t>(length >> 8);
    for (size_t i = 0; i < length; ++i) {
        scratch[2 + i] = payload[i];
    }
    return boot::crc32(scratch, 2 + length);
}

} // namespace

size_t SerialFramer::frame(const uint8_t* payload, size_t length, uint8_t* out, size_t capacity)
{
    if (payload == nullptr || length == 0 || length > kMaxMessage || capacity < length + kOverhead) {
        return 0;
    }
    out[0] = kSync0;
    out[1] = kSync1;
    out[2] = static_cast<uint8_t>(length);
    out[3] = static_cast<uint8_t>(length >> 8);
    for (size_t i = 0; i < length; ++i) {
        out[4 + i] = payload[i];
    }
    const uint32_t crc = frameCrc(payload, length);
    for (int i = 0; i < 4; ++i) {
        out[4 + length + i] = static_cast<uint8_t>(crc >> (8 * i));
    }
    return length + kOverhead;
}

void SerialFramer::reset()
{
    if (state_ != State::Sync0) {
        ++dropped_;
    }
    state_ = State::Sync0;
    at_ = 0;
}

bool SerialFramer::receive(uint8_t byte)
{
    switch (state_) {
    case State::Sync0:
        if (byte == kSync0) {
            state_ = State::Sync1;
        }
        return false;
    case State::Sync1:
        state_ = byte == kSync1 ? State::Length0 : byte == kSync0 ? State::Sync1 : State::Sync0;
        return false;
    case State::Length0:
        length_ = byte;
        state_ = State::Length1;
        return false;
    case State::Length1:
        length_ |= static_cast<size_t>(byte) << 8;
        if (length_ == 0 || length_ > kMaxMessage) {
            ++dropped_;
            state_ = State::Sync0;
            return false;
        }
        at_ = 0;
        state_ = State::Payload;
        return false;
    case State::Payload:
        buffer_[at_++] = byte;
        if (at_ == length_) {
            at_ = 0;
            state_ = State::Crc;
        }
        return false;
    case State::Crc:
        crcBytes_[at_++] = byte;
        if (at_ < 4) {
            return false;
        }
        state_ = State::Sync0;
        {
            const uint32_t received = static_cast<uint32_t>(crcBytes_[0]) | (static_cast<uint32_t>(crcBytes_[1]) << 8) |
                                      (static_cast<uint32_t>(crcBytes_[2]) << 16) |
                                      (static_cast<uint32_t>(crcBytes_[3]) << 24);
            if (received != frameCrc(buffer_, length_)) {
                ++dropped_;
                return false;
            }
        }
        return true;
    }
    return false;
}

} // namespace flash
