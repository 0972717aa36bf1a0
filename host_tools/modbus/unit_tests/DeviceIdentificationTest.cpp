// Device identification (2B/0E) frames: the simulator's answers decoded by
// the reader dcos-modbus uses, streams split to fit the ADU, exceptions,
// and the framing of answers as they arrive byte by byte.
#include <hostmodbus/DeviceIdentification.hpp>

#include <modbus/Crc16.hpp>

#include <gtest/gtest.h>

namespace {

using namespace hostmodbus;

std::vector<DeviceIdObject> objects()
{
    return {{0, "DCOS"}, {1, "SIM"}, {2, "1.0"}, {4, "Simulated drive"}};
}

DeviceIdentificationReply ask(ReadDeviceIdCode code, uint8_t object, const std::vector<DeviceIdObject>& have)
{
    const std::vector<uint8_t> pdu = deviceIdRequestPdu(code, object);
    const std::vector<uint8_t> frame = deviceIdResponseFrame(17, pdu.data(), pdu.size(), have);
    const FrameScan scan = scanDeviceIdResponse(frame.data(), frame.size());
    EXPECT_EQ(scan.state, FrameScan::State::Complete);
    EXPECT_EQ(scan.length, frame.size());
    const Result<DeviceIdentificationReply> reply = decodeDeviceIdResponse(frame.data(), frame.size(), 17);
    EXPECT_TRUE(reply.ok()) << reply.error();
    return reply.ok() ? reply.value() : DeviceIdentificationReply{};
}

TEST(ModbusDeviceIdentification, BasicRegularAndIndividual)
{
    const DeviceIdentificationReply basic = ask(ReadDeviceIdCode::Basic, 0, objects());
    ASSERT_EQ(basic.objects.size(), 3u);
    EXPECT_EQ(basic.objects[0].value, "DCOS");
    EXPECT_EQ(basic.objects[2].value, "1.0");
    EXPECT_FALSE(basic.moreFollows);
    EXPECT_EQ(basic.conformity, 0x83);
    const DeviceIdentificationReply regular = ask(ReadDeviceIdCode::Regular, 0, objects());
    ASSERT_EQ(regular.objects.size(), 4u);
    EXPECT_EQ(regular.objects[3].id, 4);
    EXPECT_EQ(deviceIdObjectName(4), "ProductName");
    const DeviceIdentificationReply one = ask(ReadDeviceIdCode::Individual, 2, objects());
    ASSERT_EQ(one.objects.size(), 1u);
    EXPECT_EQ(one.objects[0].value, "1.0");
}

TEST(ModbusDeviceIdentification, MissingObjectAndBadCodeAreExceptions)
{
    EXPECT_EQ(ask(ReadDeviceIdCode::Individual, 3, objects()).exceptionCode, 0x02);
    const uint8_t badCode[] = {0x2B, 0x0E, 0x07, 0x00};
    const std::vector<uint8_t> frame = deviceIdResponseFrame(17, badCode, sizeof badCode, objects());
    EXPECT_EQ(frame.size(), 5u);
    EXPECT_EQ(frame[1], 0xAB);
    EXPECT_EQ(frame[2], 0x03);
    // A stream that starts at an object the slave lacks starts from the first.
    EXPECT_EQ(ask(ReadDeviceIdCode::Regular, 0x33, objects()).objects.size(), 4u);
}

TEST(ModbusDeviceIdentification, LongStreamsAreSplitAndResumed)
{
    std::vector<DeviceIdObject> have = objects();
    for (uint8_t id = 0x80; id < 0x88; ++id) {
        have.push_back({id, std::string(60, static_cast<char>('a' + (id & 7)))});
    }
    std::vector<DeviceIdObject> all;
    uint8_t next = 0;
    for (int i = 0; i < 10; ++i) {
        const DeviceIdentificationReply part = ask(ReadDeviceIdCode::Extended, next, have);
        ASSERT_FALSE(part.objects.empty());
        all.insert(all.end(), part.objects.begin(), part.objects.end());
        if (!part.moreFollows) {
            break;
        }
        next = part.nextObjectId;
    }
    ASSERT_EQ(all.size(), have.size());
    for (size_t i = 0; i < all.size(); ++i) {
        EXPECT_EQ(all[i].id, have[i].id);
        EXPECT_EQ(all[i].value, have[i].value);
    }
}

TEST(ModbusDeviceIdentification, ScanWaitsForTheWholeFrameAndRefusesOthers)
{
    const std::vector<uint8_t> pdu = deviceIdRequestPdu(ReadDeviceIdCode::Basic, 0);
    const std::vector<uint8_t> frame = deviceIdResponseFrame(17, pdu.data(), pdu.size(), objects());
    for (size_t n = 0; n < frame.size(); ++n) {
        EXPECT_EQ(scanDeviceIdResponse(frame.data(), n).state, FrameScan::State::NeedMore) << n;
    }
    const uint8_t other[] = {17, 0x03, 0x02, 0x00, 0x00};
    EXPECT_EQ(scanDeviceIdResponse(other, sizeof other).state, FrameScan::State::Invalid);
}

TEST(ModbusDeviceIdentification, DecodeChecksCrcAddressAndMoreFollows)
{
    const std::vector<uint8_t> pdu = deviceIdRequestPdu(ReadDeviceIdCode::Basic, 0);
    std::vector<uint8_t> frame = deviceIdResponseFrame(17, pdu.data(), pdu.size(), objects());
    EXPECT_FALSE(decodeDeviceIdResponse(frame.data(), frame.size(), 18).ok());
    std::vector<uint8_t> damaged = frame;
    damaged[10] ^= 1; // a byte of "DCOS", not a length
    EXPECT_EQ(decodeDeviceIdResponse(damaged.data(), damaged.size(), 17).error(), "the answer's CRC is wrong");
    std::vector<uint8_t> oddMore = frame;
    oddMore[5] = 0x01;
    modbus::Crc16::append(oddMore.data(), oddMore.size() - 2);
    EXPECT_FALSE(decodeDeviceIdResponse(oddMore.data(), oddMore.size(), 17).ok());
    EXPECT_FALSE(decodeDeviceIdResponse(frame.data(), frame.size() - 1, 17).ok());
}

} // namespace
