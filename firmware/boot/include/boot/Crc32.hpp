// CRC-32 as IEEE 802.3 and zlib compute it (reflected polynomial
// 0xEDB88320, initial value and final XOR 0xFFFFFFFF), which guards the
// card's boot state and configuration records against a torn write. Not a
// defence against tampering: that is the images' signature's job.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace boot {

/// The CRC-32 of @p length bytes at @p data; "123456789" gives 0xCBF43926.
uint32_t crc32(const void* data, size_t length);

} // namespace boot
