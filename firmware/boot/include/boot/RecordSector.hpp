// The frame every record on the card shares (docs/boot.md, "The card"):
// one 512-byte sector with an 8-byte magic, the sequence at offset 8, the
// format at 12, the record's own fields from 13, and the CRC-32 of bytes 0
// to 507 at 508; numbers little-endian. BootState and ConfigurationBlock
// fill in their fields between.
#pragma once

#include <boot/CardLayout.hpp>
#include <boot/Crc32.hpp>

#include <stddef.h>
#include <stdint.h>

namespace boot::record {

constexpr size_t kSequenceOffset = 8;
constexpr size_t kFormatOffset = 12;
constexpr size_t kCrcOffset = card::kSectorSize - 4;

inline void put32(uint8_t* at, uint32_t value)
{
    for (int i = 0; i < 4; ++i) {
        at[i] = static_cast<uint8_t>(value >> (8 * i));
    }
}

inline uint32_t get32(const uint8_t* at)
{
    return static_cast<uint32_t>(at[0]) | (static_cast<uint32_t>(at[1]) << 8) |
           (static_cast<uint32_t>(at[2]) << 16) | (static_cast<uint32_t>(at[3]) << 24);
}

/// Clears the sector and writes the magic, the sequence and the format.
inline void begin(uint8_t (&sector)[card::kSectorSize], const char (&magic)[8], uint32_t sequence, uint8_t format)
{
    for (uint8_t& byte : sector) {
        byte = 0;
    }
    for (size_t i = 0; i < sizeof magic; ++i) {
        sector[i] = static_cast<uint8_t>(magic[i]);
    }
    put32(sector + kSequenceOffset, sequence);
    sector[kFormatOffset] = format;
}

/// Writes the CRC of everything before it: the record is complete.
inline void seal(uint8_t (&sector)[card::kSectorSize]) { put32(sector + kCrcOffset, crc32(sector, kCrcOffset)); }

/// True for the right magic and format and a CRC that matches.
inline bool intact(const uint8_t (&sector)[card::kSectorSize], const char (&magic)[8], uint8_t format)
{
    for (size_t i = 0; i < sizeof magic; ++i) {
        if (sector[i] != static_cast<uint8_t>(magic[i])) {
            return false;
        }
    }
    return sector[kFormatOffset] == format && get32(sector + kCrcOffset) == crc32(sector, kCrcOffset);
}

} // namespace boot::record
