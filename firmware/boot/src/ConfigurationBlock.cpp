#include <boot/ConfigurationBlock.hpp>
#include <boot/RecordSector.hpp>

namespace boot {

namespace {

using record::get32;
using record::put32;
using record::kCrcOffset;

constexpr char kMagic[8] = {'D', 'C', 'O', 'S', 'C', 'O', 'N', 'F'};
constexpr uint8_t kFormat = 1;
constexpr size_t kKeysOffset = 20;
constexpr size_t kCommandLineOffset = kKeysOffset + ConfigurationBlock::kMaximumKeys * ConfigurationBlock::kKeySize;
static_assert(kCommandLineOffset + ConfigurationBlock::kCommandLineSize <= kCrcOffset, "the record fits its sector");

} // namespace

void ConfigurationBlock::encode(uint8_t (&sector)[kSize]) const
{
    record::begin(sector, kMagic, sequence, kFormat);
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
    record::seal(sector);
}

bool ConfigurationBlock::decode(const uint8_t (&sector)[kSize], ConfigurationBlock& out)
{
    if (!record::intact(sector, kMagic, kFormat)) {
        return false;
    }
    ConfigurationBlock block;
    block.sequence = get32(sector + record::kSequenceOffset);
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
