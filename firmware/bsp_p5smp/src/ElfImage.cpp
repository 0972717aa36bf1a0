#include <bsp/ElfImage.hpp>

#include <string.h>

namespace bsp {

namespace {

// The fields read, at their offsets in a 32-bit file.
constexpr uint8_t kElfMagic[4] = {0x7F, 'E', 'L', 'F'};
constexpr size_t kClassOffset = 4;
constexpr uint8_t kClass32 = 1;
constexpr size_t kDataOffset = 5;
constexpr uint8_t kLittleEndian = 1;
constexpr size_t kTypeOffset = 16;
constexpr uint16_t kTypeExecutable = 2;
constexpr size_t kMachineOffset = 18;
constexpr uint16_t kMachine386 = 3;
constexpr size_t kEntryOffset = 24;
constexpr size_t kProgramHeaderOffset = 28;
constexpr size_t kProgramHeaderSizeOffset = 42;
constexpr size_t kProgramHeaderCountOffset = 44;
constexpr size_t kHeaderBytes = 52;
constexpr uint16_t kProgramHeaderBytes = 32;
constexpr uint32_t kSegmentLoad = 1;
// Program header fields.
constexpr size_t kSegmentType = 0;
constexpr size_t kSegmentFileOffset = 4;
constexpr size_t kSegmentPhysical = 12;
constexpr size_t kSegmentFileBytes = 16;
constexpr size_t kSegmentMemoryBytes = 20;

uint16_t read16(const uint8_t* at)
{
    uint16_t value;
    memcpy(&value, at, sizeof value);
    return value;
}

uint32_t read32(const uint8_t* at)
{
    uint32_t value;
    memcpy(&value, at, sizeof value);
    return value;
}

} // namespace

uint16_t ElfImage::segmentCount(const uint8_t* image) { return read16(image + kProgramHeaderCountOffset); }

bool ElfImage::loadableAt(const uint8_t* image, uint16_t index, Segment& segment)
{
    const uint8_t* header = image + read32(image + kProgramHeaderOffset) + uint32_t{index} * kProgramHeaderBytes;
    segment = {read32(header + kSegmentFileOffset), read32(header + kSegmentPhysical),
               read32(header + kSegmentFileBytes), read32(header + kSegmentMemoryBytes)};
    return read32(header + kSegmentType) == kSegmentLoad;
}

bool ElfImage::check(const uint8_t* image, size_t bytes, uint32_t base, uint32_t end, uint32_t& entry)
{
    if (image == nullptr || bytes < kHeaderBytes || memcmp(image, kElfMagic, sizeof kElfMagic) != 0 ||
        image[kClassOffset] != kClass32 || image[kDataOffset] != kLittleEndian ||
        read16(image + kTypeOffset) != kTypeExecutable || read16(image + kMachineOffset) != kMachine386 ||
        read16(image + kProgramHeaderSizeOffset) != kProgramHeaderBytes) {
        return false;
    }
    const uint32_t headers = read32(image + kProgramHeaderOffset);
    const uint16_t count = segmentCount(image);
    if (count == 0 || count > kMaximumSegments || headers > bytes ||
        uint32_t{count} * kProgramHeaderBytes > bytes - headers) {
        return false;
    }
    const uint32_t candidate = read32(image + kEntryOffset);
    bool entryInside = false;
    for (uint16_t i = 0; i < count; ++i) {
        Segment segment{};
        if (!loadableAt(image, i, segment)) {
            continue;
        }
        if (segment.fileBytes > segment.memoryBytes || segment.fileOffset > bytes ||
            segment.fileBytes > bytes - segment.fileOffset || segment.physical < base || segment.physical >= end ||
            segment.memoryBytes > end - segment.physical) {
            return false;
        }
        entryInside = entryInside || (candidate >= segment.physical && candidate - segment.physical < segment.fileBytes);
    }
    if (!entryInside) {
        return false;
    }
    entry = candidate;
    return true;
}

} // namespace bsp
