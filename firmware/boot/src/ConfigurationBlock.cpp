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
constexpr size_t kSerialOffset = kCommandLineOffset + ConfigurationBlock::kCommandLineSize;
constexpr size_t kConfigurationKeyOffset = kSerialOffset + 4;
constexpr size_t kFlagsOffset = kConfigurationKeyOffset + ConfigurationBlock::kConfigurationKeySize;
constexpr size_t kLockoutOffset = kFlagsOffset + 1;
static_assert(kSerialOffset == 440 && kFlagsOffset == 476, "the layout of ConfigurationBlock.hpp");
static_assert(kLockoutOffset + 2 <= kCrcOffset, "the record fits its sector");

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
    put32(sector + kSerialOffset, serialNumber);
    for (size_t i = 0; i < kConfigurationKeySize; ++i) {
        sector[kConfigurationKeyOffset + i] = hasConfigurationKey() ? configurationKey[i] : 0;
    }
    sector[kFlagsOffset] = flags;
    sector[kLockoutOffset] = static_cast<uint8_t>(lockoutSeconds);
    sector[kLockoutOffset + 1] = static_cast<uint8_t>(lockoutSeconds >> 8);
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
    block.serialNumber = get32(sector + kSerialOffset);
    block.flags = sector[kFlagsOffset];
    if ((block.flags & ~kKnownFlags) != 0) {
        return false;
    }
    for (size_t i = 0; i < kConfigurationKeySize; ++i) {
        block.configurationKey[i] = sector[kConfigurationKeyOffset + i];
    }
    block.lockoutSeconds = static_cast<uint16_t>(sector[kLockoutOffset] | (sector[kLockoutOffset + 1] << 8));
    out = block;
    return true;
}

} // namespace boot
