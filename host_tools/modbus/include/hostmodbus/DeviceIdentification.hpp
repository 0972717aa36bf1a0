// Read Device Identification (function 2B, MEI type 0E, [AP] 6.21) on the
// host. libmodbus has no call for it, and its modbus_receive_confirmation()
// would take the MEI type for a byte count, so dcos-modbus sends the request
// with modbus_send_raw_request() and frames the answer here; dcos-modbus-sim
// builds its answers here too. The frames are whole RTU ADUs: address, PDU,
// CRC (fieldbus/modbus's Crc16).
#pragma once

#include <hostmodbus/Result.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hostmodbus {

constexpr uint8_t kFunctionEncapsulated = 0x2B;
constexpr uint8_t kMeiDeviceIdentification = 0x0E;

/// Read device ID codes ([AP] 6.21): a stream of the basic, regular or
/// extended objects, or one object.
enum class ReadDeviceIdCode : uint8_t { Basic = 1, Regular = 2, Extended = 3, Individual = 4 };

struct DeviceIdObject {
    uint8_t id = 0;
    std::string value;
};

struct DeviceIdentificationReply {
    /// Set when the slave answered with an exception: its code, and nothing else.
    uint8_t exceptionCode = 0;
    uint8_t readCode = 0;
    uint8_t conformity = 0;
    bool moreFollows = false;
    uint8_t nextObjectId = 0;
    std::vector<DeviceIdObject> objects;
};

/// The request PDU (no address, no CRC), as modbus_send_raw_request() takes
/// it after the address.
std::vector<uint8_t> deviceIdRequestPdu(ReadDeviceIdCode code, uint8_t objectId);

/// How much of a response frame has arrived.
struct FrameScan {
    enum class State { NeedMore, Complete, Invalid } state = State::NeedMore;
    /// The whole frame's length when Complete.
    size_t length = 0;
};

/// Scans the bytes of a response received so far: complete when the frame's
/// own lengths say so, invalid when they cannot belong to a 2B/0E answer or
/// to its exception (so the reader stops rather than waits for its time-out).
FrameScan scanDeviceIdResponse(const uint8_t* bytes, size_t size);

/// Decodes a complete response frame from @p slave: checks the CRC, the
/// address, the function and every object's length.
Result<DeviceIdentificationReply> decodeDeviceIdResponse(const uint8_t* bytes, size_t size, uint8_t slave);

/// The object's name in [AP] Table 6.21 ("VendorName", ...), or "object 0xNN".
std::string deviceIdObjectName(uint8_t id);

/// The response frame a slave with @p objects (sorted by id, at most 255
/// bytes each) sends to the request PDU @p request, exceptions included
/// (illegal data value for a bad code, illegal data address for an
/// object it does not have). Streams are split to fit the 256-byte ADU.
std::vector<uint8_t> deviceIdResponseFrame(uint8_t slave, const uint8_t* request, size_t requestSize,
                                           const std::vector<DeviceIdObject>& objects);

} // namespace hostmodbus
