#include <modbus/Crc16.hpp>

namespace modbus {

namespace {

// One entry per value of the register's low byte: the effect of shifting
// those eight bits out, built at compile time from the bitwise definition.
struct Crc16Table {
    uint16_t entries[256];

    constexpr Crc16Table() : entries()
    {
        for (unsigned value = 0; value < 256; ++value) {
            uint16_t crc = static_cast<uint16_t>(value);
            for (int bit = 0; bit < 8; ++bit) {
                crc = (crc & 1) != 0 ? static_cast<uint16_t>((crc >> 1) ^ Crc16::kPolynomial)
                                     : static_cast<uint16_t>(crc >> 1);
            }
            entries[value] = crc;
        }
    }
};

constexpr Crc16Table kTable;
// Spot checks against the bitwise definition, so a broken table stops the build.
static_assert(kTable.entries[0] == 0x0000 && kTable.entries[1] == 0xC0C1 && kTable.entries[0xFF] == 0x4040,
              "CRC-16/MODBUS table");

} // namespace

uint16_t Crc16::update(uint16_t crc, const uint8_t* bytes, size_t length)
{
    for (size_t i = 0; i < length; ++i) {
        crc = static_cast<uint16_t>((crc >> 8) ^ kTable.entries[(crc ^ bytes[i]) & 0xFF]);
    }
    return crc;
}

bool Crc16::check(const uint8_t* frame, size_t length)
{
    if (frame == nullptr || length < 3) {
        return false;
    }
    const uint16_t crc = compute(frame, length - 2);
    return frame[length - 2] == (crc & 0xFF) && frame[length - 1] == (crc >> 8);
}

void Crc16::append(uint8_t* frame, size_t length)
{
    const uint16_t crc = compute(frame, length);
    frame[length] = static_cast<uint8_t>(crc & 0xFF);
    frame[length + 1] = static_cast<uint8_t>(crc >> 8);
}

} // namespace modbus
