// Crc16: the CRC of RTU frames against frames whose CRC is published.
#include <modbus/Crc16.hpp>

#include "ModbusTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using modbus::Crc16;
using namespace modbus_test;

// Reference: the bitwise algorithm of [SL] 6.2.2, written out here
// independently of the table the library builds.
uint16_t bitwise(const Bytes& bytes)
{
    uint16_t crc = 0xFFFF;
    for (uint8_t byte : bytes) {
        crc ^= byte;
        for (int bit = 0; bit < 8; ++bit) {
            crc = (crc & 1) ? static_cast<uint16_t>((crc >> 1) ^ 0xA001) : static_cast<uint16_t>(crc >> 1);
        }
    }
    return crc;
}

TEST(Crc16Test, SerialLineSpecificationExample)
{
    // [SL] 6.2.2: function 07 to slave 02 has the CRC 0x1241, sent 41 12.
    const Bytes frame = {0x02, 0x07};
    EXPECT_EQ(Crc16::compute(frame.data(), frame.size()), 0x1241);
    EXPECT_EQ(withCrc(frame), (Bytes{0x02, 0x07, 0x41, 0x12}));
}

TEST(Crc16Test, KnownRequests)
{
    // Read 10 holding registers from 0 at slave 1: the request every Modbus
    // tool prints, 01 03 00 00 00 0A C5 CD.
    EXPECT_EQ(withCrc({0x01, 0x03, 0x00, 0x00, 0x00, 0x0A}), (Bytes{0x01, 0x03, 0x00, 0x00, 0x00, 0x0A, 0xC5, 0xCD}));
    // [AP] 6.3's example request (registers 108..110) at slave 0x11.
    EXPECT_EQ(withCrc({0x11, 0x03, 0x00, 0x6B, 0x00, 0x03}), (Bytes{0x11, 0x03, 0x00, 0x6B, 0x00, 0x03, 0x76, 0x87}));
    // [AP] 6.5's example, coil 173 on, at slave 1.
    EXPECT_EQ(withCrc({0x01, 0x05, 0x00, 0xAC, 0xFF, 0x00}), (Bytes{0x01, 0x05, 0x00, 0xAC, 0xFF, 0x00, 0x4C, 0x1B}));
    EXPECT_EQ(withCrc({0x01, 0x04, 0x00, 0x00, 0x00, 0x01}), (Bytes{0x01, 0x04, 0x00, 0x00, 0x00, 0x01, 0x31, 0xCA}));
}

TEST(Crc16Test, EmptyInputIsTheInitialValue)
{
    EXPECT_EQ(Crc16::compute(nullptr, 0), 0xFFFF);
}

TEST(Crc16Test, TableMatchesTheBitwiseDefinitionForEveryByteAndLongFrames)
{
    for (int value = 0; value < 256; ++value) {
        const Bytes one = {static_cast<uint8_t>(value)};
        ASSERT_EQ(Crc16::compute(one.data(), 1), bitwise(one)) << value;
    }
    Bytes frame;
    for (int i = 0; i < 256; ++i) {
        frame.push_back(static_cast<uint8_t>(i * 37 + 11));
    }
    EXPECT_EQ(Crc16::compute(frame.data(), frame.size()), bitwise(frame));
}

TEST(Crc16Test, UpdateContinuesAcrossPieces)
{
    const Bytes frame = {0x11, 0x03, 0x00, 0x6B, 0x00, 0x03};
    const uint16_t first = Crc16::update(Crc16::kInitial, frame.data(), 2);
    EXPECT_EQ(Crc16::update(first, frame.data() + 2, 4), Crc16::compute(frame.data(), frame.size()));
}

TEST(Crc16Test, CheckAcceptsGoodFramesOnly)
{
    Bytes frame = withCrc({0x01, 0x03, 0x00, 0x00, 0x00, 0x0A});
    EXPECT_TRUE(Crc16::check(frame.data(), frame.size()));
    // Every single-bit error is detected.
    for (size_t bit = 0; bit < frame.size() * 8; ++bit) {
        Bytes corrupted = frame;
        corrupted[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
        EXPECT_FALSE(Crc16::check(corrupted.data(), corrupted.size())) << bit;
    }
    // The CRC bytes swapped (high byte first) is wrong.
    std::swap(frame[6], frame[7]);
    EXPECT_FALSE(Crc16::check(frame.data(), frame.size()));
    EXPECT_FALSE(Crc16::check(frame.data(), 2));
    EXPECT_FALSE(Crc16::check(nullptr, 8));
}

TEST(Crc16Test, AppendWritesLowByteFirst)
{
    uint8_t frame[4] = {0x02, 0x07, 0, 0};
    Crc16::append(frame, 2);
    EXPECT_EQ(frame[2], 0x41);
    EXPECT_EQ(frame[3], 0x12);
}

} // namespace
