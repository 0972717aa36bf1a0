#include <hostimage/ElfPayload.hpp>

#include <algorithm>

namespace hostimage {

namespace {

// The ELF header's and program header's fields used here (System V ABI,
// "ELF Header" and "Program Header"; the i386 supplement for EM_386).
constexpr size_t kElfHeaderSize = 52;
constexpr size_t kProgramHeaderSize = 32;
constexpr uint8_t kClass32 = 1;       // e_ident[EI_CLASS]: ELFCLASS32
constexpr uint8_t kLittleEndian = 1;  // e_ident[EI_DATA]: ELFDATA2LSB
constexpr uint16_t kExecutable = 2;   // e_type: ET_EXEC
constexpr uint16_t kMachine386 = 3;   // e_machine: EM_386
constexpr uint32_t kLoadSegment = 1;  // p_type: PT_LOAD
constexpr size_t kTypeOffset = 16;
constexpr size_t kMachineOffset = 18;
constexpr size_t kEntryOffset = 24;
constexpr size_t kProgramHeaderOffset = 28;
constexpr size_t kProgramHeaderEntrySizeOffset = 42;
constexpr size_t kProgramHeaderCountOffset = 44;
// The program header's fields.
constexpr size_t kSegmentTypeOffset = 0;
constexpr size_t kSegmentFileOffset = 4;
constexpr size_t kSegmentPhysicalAddressOffset = 12;
constexpr size_t kSegmentFileSizeOffset = 16;
constexpr size_t kSegmentMemorySizeOffset = 20;

uint16_t read16(const std::vector<uint8_t>& file, size_t at)
{
    return static_cast<uint16_t>(file[at] | (file[at + 1] << 8));
}

uint32_t read32(const std::vector<uint8_t>& file, size_t at)
{
    return static_cast<uint32_t>(file[at]) | (static_cast<uint32_t>(file[at + 1]) << 8) |
           (static_cast<uint32_t>(file[at + 2]) << 16) | (static_cast<uint32_t>(file[at + 3]) << 24);
}

struct Segment {
    uint32_t fileOffset;
    uint32_t address; // p_paddr: where the loader puts it.
    uint32_t fileSize;
    uint32_t memorySize;
};

} // namespace

std::optional<ElfPayload> ElfPayload::fromElf(const std::vector<uint8_t>& file, std::string& error)
{
    if (file.size() < kElfHeaderSize || file[0] != 0x7F || file[1] != 'E' || file[2] != 'L' || file[3] != 'F') {
        error = "not an ELF file";
        return std::nullopt;
    }
    if (file[4] != kClass32 || file[5] != kLittleEndian) {
        error = "not a 32-bit little-endian ELF file";
        return std::nullopt;
    }
    if (read16(file, kTypeOffset) != kExecutable || read16(file, kMachineOffset) != kMachine386) {
        error = "not an i386 executable (ET_EXEC, EM_386): link the firmware first";
        return std::nullopt;
    }
    const uint32_t tableOffset = read32(file, kProgramHeaderOffset);
    const uint16_t entrySize = read16(file, kProgramHeaderEntrySizeOffset);
    const uint16_t count = read16(file, kProgramHeaderCountOffset);
    if (entrySize < kProgramHeaderSize || uint64_t{tableOffset} + uint64_t{entrySize} * count > file.size()) {
        error = "program headers outside the file";
        return std::nullopt;
    }
    std::vector<Segment> segments;
    for (uint16_t i = 0; i < count; ++i) {
        const size_t at = tableOffset + size_t{entrySize} * i;
        if (read32(file, at + kSegmentTypeOffset) != kLoadSegment) {
            continue;
        }
        const Segment segment{read32(file, at + kSegmentFileOffset), read32(file, at + kSegmentPhysicalAddressOffset),
                              read32(file, at + kSegmentFileSizeOffset), read32(file, at + kSegmentMemorySizeOffset)};
        if (segment.memorySize == 0) {
            continue;
        }
        if (segment.fileSize > segment.memorySize ||
            uint64_t{segment.fileOffset} + segment.fileSize > file.size() ||
            uint64_t{segment.address} + segment.memorySize > (uint64_t{1} << 32)) {
            error = "a loadable segment lies outside the file or the address space";
            return std::nullopt;
        }
        segments.push_back(segment);
    }
    if (segments.empty()) {
        error = "no loadable segment";
        return std::nullopt;
    }
    std::sort(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) { return a.address < b.address; });
    for (size_t i = 1; i < segments.size(); ++i) {
        if (uint64_t{segments[i - 1].address} + segments[i - 1].memorySize > segments[i].address) {
            error = "loadable segments overlap";
            return std::nullopt;
        }
    }
    const uint32_t base = segments.front().address;
    uint64_t payloadEnd = base;
    uint64_t memoryEnd = base;
    for (const Segment& segment : segments) {
        if (segment.fileSize != 0) {
            payloadEnd = uint64_t{segment.address} + segment.fileSize;
        }
        memoryEnd = uint64_t{segment.address} + segment.memorySize;
    }
    // A segment with file bytes after one with zeroed memory puts that
    // memory into the payload, as zeros: the loader zeroes only the end.
    if (payloadEnd == base) {
        error = "the loadable segments hold no bytes";
        return std::nullopt;
    }
    if (payloadEnd - base > kMaximumPayload || memoryEnd - base > kMaximumMemory) {
        error = "the loadable segments span more than an image may hold";
        return std::nullopt;
    }
    ElfPayload payload;
    payload.loadAddress_ = base;
    payload.memorySize_ = static_cast<uint32_t>(memoryEnd - base);
    payload.bytes_.assign(static_cast<size_t>(payloadEnd - base), 0);
    for (const Segment& segment : segments) {
        std::copy_n(file.begin() + segment.fileOffset, segment.fileSize,
                    payload.bytes_.begin() + (segment.address - base));
    }
    payload.entry_ = read32(file, kEntryOffset);
    if (payload.entry_ < base || payload.entry_ - base >= payload.bytes_.size()) {
        error = "the entry point lies outside the loaded bytes";
        return std::nullopt;
    }
    return payload;
}

} // namespace hostimage
