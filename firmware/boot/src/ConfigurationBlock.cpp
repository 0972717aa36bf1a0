#include <boot/ConfigurationBlock.hpp>
#include <boot/Crc32.hpp>

namespace boot {

namespace {

constexpr char kMagic[8] = {'D', 'C', 'O', 'S', 'C', 'O', 'N', 'F'};
constexpr uint8_t kFormat = 1;
constexpr size_t kKeysOffset = 20;
constexpr size_t kCommandLineOffset = kKeysOffset + ConfigurationBlock::kMaximumKeys * ConfigurationBlock::kKeySize;
constexpr size_t kCrcOffset = ConfigurationBlock::kSize - 4;
static_assert(kCommandLineOffset + ConfigurationBlock::kCommandLineSize <= kCrcOffset, "the record fits its sector");

void put32(uint8_t* at, uint32_t value)
{
    for (int i = 0; i < 4; ++i) {
        at[i] = static_cast<uint8_t>(value >> (8 * i));
    }
}

uint32_t get32(const uint8_t* at)
{
    return static_cast<uint32_t>(at[0]) | (static_cast<uint32_t>(at[1]) << 8) |
           (static_cast<uint32_t>(at[2]) << 16) | (static_cast<uint32_t>(at[3]) << 24);
}

} // namespace

void ConfigurationBlock::encode(uint8_t (&sector)[kSize]) const
{
    for (uint8_t& byte : sector) {
        byte = 0;
    }
    for (size_t i = 0; i < sizeof kMagic; ++i) {
        sector[i] = static_cast<uint8_t>(kMagic[i]);
    }
    put32(sector + 8, sequence);
    sector[12] = kFormat;
    sector[13] = keyCount;
    sector[14] = static_cast<uint8_t>(nodeId);
    sector[15] = static_cast<uint8_t>(nodeId >> 8);
    put32(sector + 16, canBitRate);
    for (size_t key = 0; key < kMaximumKeys; ++key) {
        for (size_t i = 0; i < kKeySize; ++i) {
            sector[kKeysOffset + key * kKeySize + i] = key < keyCount ? keys[key][i] : 0;
        }
    }
    for (size_t i = 0; i + 1 < kCommandLineSize && commandLine[i] != '\0'; ++i) {
        sector[kCommandLineOffset + i] = static_cast<uint8_t>(commandLine[i]);
    }
    put32(sector + kCrcOffset, crc32(sector, kCrcOffset));
}

bool ConfigurationBlock::decode(const uint8_t (&sector)[kSize], ConfigurationBlock& out)
{
    for (size_t i = 0; i < sizeof kMagic; ++i) {
        if (sector[i] != static_cast<uint8_t>(kMagic[i])) {
            return false;
        }
    }
    if (sector[12] != kFormat || get32(sector + kCrcOffset) != crc32(sector, kCrcOffset)) {
        return false;
    }
    ConfigurationBlock block;
    block.sequence = get32(sector + 8);
    block.keyCount = sector[13];
    block.nodeId = static_cast<uint16_t>(sector[14] | (sector[15] << 8));
    block.canBitRate = get32(sector + 16);
    if (block.keyCount > kMaximumKeys || block.nodeId == 0xFFFF) {
        return false;
    }
    for (size_t key = 0; key < block.keyCount; ++key) {
        if (sector[kKeysOffset + key * kKeySize] != 0x04) {
            return false;
        }
        for (size_t i = 0; i < kKeySize; ++i) {
            block.keys[key][i] = sector[kKeysOffset + key * kKeySize + i];
        }
    }
    size_t length = 0;
    while (length < kCommandLineSize && sector[kCommandLineOffset + length] != 0) {
        const uint8_t character = sector[kCommandLineOffset + length];
        if (character < 0x20 || character > 0x7E) {
            return false;
        }
        block.commandLine[length] = static_cast<char>(character);
        ++length;
    }
    if (length == kCommandLineSize) {
        return false; // Not terminated.
    }
    out = block;
    return true;
}

} // namespace boot
