// 16-bit fields as Modbus puts them on the wire: big-endian, high byte first
// ([AP] 4.2), everywhere except the RTU CRC (Crc16.hpp).
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace modbus {

/// The big-endian 16-bit field at @p bytes.
inline constexpr uint16_t readU16(const uint8_t* bytes)
{
    return static_cast<uint16_t>((bytes[0] << 8) | bytes[1]);
}

/// Writes @p value big-endian at @p bytes.
inline constexpr void writeU16(uint8_t* bytes, uint16_t value)
{
    bytes[0] = static_cast<uint8_t>(value >> 8);
    bytes[1] = static_cast<uint8_t>(value & 0xFF);
}

/// Bytes needed for @p quantity packed bits.
inline constexpr size_t bitBytes(size_t quantity)
{
    return (quantity + 7) / 8;
}

} // namespace modbus
