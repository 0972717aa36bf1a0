// Helpers shared by the Modbus tests: byte vectors, RTU frames with their
// CRC, and the timing of a 19200 baud line where one character is 11 bits.
#pragma once

#include <modbus/Crc16.hpp>
#include <modbus/RtuTiming.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace modbus_test {

using Bytes = std::vector<uint8_t>;

/// @p bytes with their CRC appended, low byte first.
inline Bytes withCrc(Bytes bytes)
{
    const uint16_t crc = modbus::Crc16::compute(bytes.data(), bytes.size());
    bytes.push_back(static_cast<uint8_t>(crc & 0xFF));
    bytes.push_back(static_cast<uint8_t>(crc >> 8));
    return bytes;
}

inline Bytes bytesOf(const uint8_t* data, size_t length)
{
    return Bytes(data, data + length);
}

/// 19200 baud, 11 bits: a character is 572917 ns (rounded up), t1.5 859375 ns, t3.5 2005209 ns.
inline modbus::RtuTiming timing19200()
{
    const auto timing = modbus::RtuTiming::make(19200);
    EXPECT_TRUE(timing.ok());
    return timing.value();
}

} // namespace modbus_test

namespace modbus_test {

/// One character at 19200 baud, and the silences of that line.
inline constexpr uint64_t kChar19200 = 572917;
inline constexpr uint64_t kT35At19200 = 2005209;

/// Feeds @p bytes to @p station back to back, the first one ending
/// @p startNs; returns when the last ended and, in @p last, the last step.
template <typename Station, typename Step>
uint64_t feed(Station& station, const Bytes& bytes, uint64_t startNs, Step& last)
{
    uint64_t now = startNs;
    for (size_t i = 0; i < bytes.size(); ++i) {
        if (i > 0) {
            now += kChar19200;
        }
        last = station.onBytes(&bytes[i], 1, now);
    }
    return now;
}

} // namespace modbus_test
