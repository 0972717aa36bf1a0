#include <boot/Crc32.hpp>

namespace boot {

namespace {

// The table of the byte-at-a-time algorithm, computed at compile time.
struct Table {
    uint32_t entries[256];

    constexpr Table() : entries()
    {
        for (uint32_t i = 0; i < 256; ++i) {
            uint32_t value = i;
            for (int bit = 0; bit < 8; ++bit) {
                value = (value & 1) != 0 ? (value >> 1) ^ 0xEDB88320u : value >> 1;
            }
            entries[i] = value;
        }
    }
};

constexpr Table kTable;
static_assert(kTable.entries[1] == 0x77073096u, "the reflected IEEE polynomial's table");

} // namespace

uint32_t crc32(const void* data, size_t length)
{
    const auto* bytes = static_cast<const uint8_t*>(data);
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < length; ++i) {
        crc = kTable.entries[(crc ^ bytes[i]) & 0xFF] ^ (crc >> 8);
    }
    return crc ^ 0xFFFFFFFFu;
}

} // namespace boot
