#include <hostmodbus/DeviceIdentification.hpp>

#include <modbus/Crc16.hpp>

#include <fmt/core.h>

#include <algorithm>

namespace hostmodbus {

namespace {

// Address, function, MEI type, read code, conformity, more follows, next
// object id and number of objects: the fixed part before the objects.
constexpr size_t kHeaderSize = 8;
constexpr size_t kCrcSize = 2;
constexpr size_t kExceptionFrameSize = 5;
constexpr size_t kMaxFrameSize = 256;
constexpr uint8_t kExceptionBit = 0x80;
constexpr uint8_t kIllegalDataAddress = 0x02;
constexpr uint8_t kIllegalDataValue = 0x03;
// Conformity level 0x83: basic, regular and extended objects, stream and
// individual access ([AP] 6.21).
constexpr uint8_t kConformity = 0x83;

std::vector<uint8_t> exceptionFrame(uint8_t slave, uint8_t code)
{
    std::vector<uint8_t> frame{slave, static_cast<uint8_t>(kFunctionEncapsulated | kExceptionBit), code, 0, 0};
    modbus::Crc16::append(frame.data(), 3);
    return frame;
}

// Which objects a stream of the given code covers. [AP] 6.21 puts objects
// 0..2 in the basic category, 3..0x7F in the regular and 0x80..0xFF in the
// extended one; each level includes the ones below it, as the conformity
// levels do and as pymodbus answers.
bool inCategory(uint8_t id, uint8_t code)
{
    switch (code) {
    case 1: return id <= 0x02;
    case 2: return id <= 0x7F;
    case 3: return true;
    default: return false;
    }
}

} // namespace

std::vector<uint8_t> deviceIdRequestPdu(ReadDeviceIdCode code, uint8_t objectId)
{
    return {kFunctionEncapsulated, kMeiDeviceIdentification, static_cast<uint8_t>(code), objectId};
}

FrameScan scanDeviceIdResponse(const uint8_t* bytes, size_t size)
{
    FrameScan scan;
    if (size < 2) {
        return scan;
    }
    if (bytes[1] == (kFunctionEncapsulated | kExceptionBit)) {
        if (size >= kExceptionFrameSize) {
            scan.state = FrameScan::State::Complete;
            scan.length = kExceptionFrameSize;
        }
        return scan;
    }
    if (bytes[1] != kFunctionEncapsulated) {
        scan.state = FrameScan::State::Invalid;
        return scan;
    }
    if (size < kHeaderSize) {
        return scan;
    }
    size_t length = kHeaderSize;
    const uint8_t count = bytes[7];
    for (uint8_t i = 0; i < count; ++i) {
        // Each object is an id, a length and that many bytes.
        if (size < length + 2) {
            return scan;
        }
        length += 2 + bytes[length + 1];
        if (length + kCrcSize > kMaxFrameSize) {
            scan.state = FrameScan::State::Invalid;
            return scan;
        }
    }
    length += kCrcSize;
    if (length > kMaxFrameSize) {
        scan.state = FrameScan::State::Invalid;
    } else if (size >= length) {
        scan.state = FrameScan::State::Complete;
        scan.length = length;
    }
    return scan;
}

Result<DeviceIdentificationReply> decodeDeviceIdResponse(const uint8_t* bytes, size_t size, uint8_t slave)
{
    using R = Result<DeviceIdentificationReply>;
    const FrameScan scan = scanDeviceIdResponse(bytes, size);
    if (scan.state != FrameScan::State::Complete || scan.length != size) {
        return R::failure(fmt::format("the answer of {} bytes is not a whole device identification response", size));
    }
    if (!modbus::Crc16::check(bytes, size)) {
        return R::failure("the answer's CRC is wrong");
    }
    if (bytes[0] != slave) {
        return R::failure(fmt::format("the answer came from slave {}, not {}", bytes[0], slave));
    }
    DeviceIdentificationReply reply;
    if (bytes[1] & kExceptionBit) {
        reply.exceptionCode = bytes[2];
        return R::success(reply);
    }
    if (bytes[2] != kMeiDeviceIdentification) {
        return R::failure(fmt::format("the answer's MEI type is 0x{:02X}, not 0x0E", bytes[2]));
    }
    reply.readCode = bytes[3];
    reply.conformity = bytes[4];
    if (bytes[5] != 0x00 && bytes[5] != 0xFF) {
        return R::failure(fmt::format("the answer's 'more follows' is 0x{:02X}, neither 00 nor FF", bytes[5]));
    }
    reply.moreFollows = bytes[5] == 0xFF;
    reply.nextObjectId = bytes[6];
    size_t position = kHeaderSize;
    for (uint8_t i = 0; i < bytes[7]; ++i) {
        const uint8_t length = bytes[position + 1];
        reply.objects.push_back(
            {bytes[position], std::string(reinterpret_cast<const char*>(bytes + position + 2), length)});
        position += 2 + length;
    }
    return R::success(std::move(reply));
}

std::string deviceIdObjectName(uint8_t id)
{
    static const char* const kNames[] = {"VendorName", "ProductCode", "MajorMinorRevision", "VendorUrl",
                                         "ProductName", "ModelName", "UserApplicationName"};
    return id < std::size(kNames) ? kNames[id] : fmt::format("object 0x{:02X}", id);
}

std::vector<uint8_t> deviceIdResponseFrame(uint8_t slave, const uint8_t* request, size_t requestSize,
                                           const std::vector<DeviceIdObject>& objects)
{
    if (requestSize != 4 || request[0] != kFunctionEncapsulated || request[1] != kMeiDeviceIdentification) {
        return exceptionFrame(slave, kIllegalDataValue);
    }
    const uint8_t code = request[2];
    uint8_t first = request[3];
    if (code < 1 || code > 4) {
        return exceptionFrame(slave, kIllegalDataValue);
    }
    const auto has = [&](uint8_t id) {
        return std::any_of(objects.begin(), objects.end(), [id](const DeviceIdObject& o) { return o.id == id; });
    };
    if (code == 4 && !has(first)) {
        return exceptionFrame(slave, kIllegalDataAddress);
    }
    // A stream asked to start at an object the slave lacks starts at the
    // category's first ([AP] 6.21: "the object Id is set to 0").
    if (code != 4 && (!has(first) || !inCategory(first, code))) {
        first = 0x00;
    }
    std::vector<uint8_t> frame{slave, kFunctionEncapsulated, kMeiDeviceIdentification, code, kConformity, 0x00, 0x00,
                               0x00};
    uint8_t count = 0;
    for (const DeviceIdObject& object : objects) {
        const bool wanted = code == 4 ? object.id == first : inCategory(object.id, code) && object.id >= first;
        if (!wanted) {
            continue;
        }
        const size_t length = std::min<size_t>(object.value.size(), 255);
        if (frame.size() + 2 + length + kCrcSize > kMaxFrameSize) {
            // The rest comes in the next request, from this object on.
            frame[5] = 0xFF;
            frame[6] = object.id;
            break;
        }
        frame.push_back(object.id);
        frame.push_back(static_cast<uint8_t>(length));
        frame.insert(frame.end(), object.value.begin(), object.value.begin() + static_cast<long>(length));
        ++count;
    }
    frame[7] = count;
    frame.resize(frame.size() + kCrcSize);
    modbus::Crc16::append(frame.data(), frame.size() - kCrcSize);
    return frame;
}

} // namespace hostmodbus
