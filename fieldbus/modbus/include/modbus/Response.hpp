// Read access to a response PDU that checkResponse() accepted: the values of
// a read, the objects of a device identification. The view points into the
// caller's buffer and copies nothing.
#pragma once

#include <modbus/Protocol.hpp>
#include <modbus/Wire.hpp>

#include <stddef.h>
#include <stdint.h>

namespace modbus {

/// One object of a Read Device Identification response.
struct DeviceIdObject {
    uint8_t id = 0;
    uint8_t length = 0;
    const uint8_t* value = nullptr;  ///< ASCII, not NUL-terminated.
};

class ResponseView {
public:
    ResponseView() = default;
    /// A view of the @p length bytes at @p pdu.
    ResponseView(const uint8_t* pdu, size_t length) : pdu_(pdu), length_(length) {}

    const uint8_t* pdu() const { return pdu_; }
    size_t length() const { return length_; }
    uint8_t function() const { return length_ > 0 ? pdu_[0] : 0; }

    /// Registers in a response of function 03, 04 or 17.
    size_t registerCount() const { return length_ >= 2 ? pdu_[1] / 2 : 0; }
    /// Register @p index of such a response; 0 past the end.
    uint16_t registerValue(size_t index) const
    {
        return index < registerCount() ? readU16(pdu_ + 2 + 2 * index) : 0;
    }

    /// Bit @p index of a response of function 01 or 02; false past the
    /// bytes it has (the caller knows the quantity it asked for).
    bool bit(size_t index) const
    {
        return length_ >= 2 && index / 8 < pdu_[1] ? ((pdu_[2 + index / 8] >> (index % 8)) & 1) != 0 : false;
    }

    /// Read Device Identification: whether more objects follow, and from which id.
    bool moreFollows() const { return length_ >= kDeviceIdHeaderLength && pdu_[4] == kMoreFollows; }
    uint8_t nextObjectId() const { return length_ >= kDeviceIdHeaderLength ? pdu_[5] : 0; }
    uint8_t conformityLevel() const { return length_ >= kDeviceIdHeaderLength ? pdu_[3] : 0; }
    size_t objectCount() const { return length_ >= kDeviceIdHeaderLength ? pdu_[6] : 0; }
    /// Object @p index of the response in @p object; false past the last.
    bool object(size_t index, DeviceIdObject& object) const;

private:
    const uint8_t* pdu_ = nullptr;
    size_t length_ = 0;
};

} // namespace modbus
