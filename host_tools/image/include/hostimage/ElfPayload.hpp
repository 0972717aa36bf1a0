// The payload of a controller image taken from a linked firmware ELF file
// (docs/boot.md, "Controller images"): the bytes of its loadable segments
// laid out from the lowest load address, the gaps between them zero, and
// the memory they span with the zeroed part (.bss) at the end.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hostimage {

class ElfPayload {
public:
    /// The largest payload and memory span taken: far above any DCOS
    /// image (the 486 board's full image is some 200 KiB), low enough that
    /// a malformed file cannot make the tool allocate gigabytes.
    static constexpr uint32_t kMaximumPayload = 16u << 20;
    static constexpr uint32_t kMaximumMemory = 64u << 20;

    /// Reads a 32-bit little-endian i386 executable (ET_EXEC) from @p file.
    /// Refuses, with the reason in @p error, anything else: another class,
    /// byte order, machine or type, headers or segments outside the file,
    /// overlapping segments, no loadable segment, an entry outside the
    /// loaded bytes, a payload or span above the limits above.
    static std::optional<ElfPayload> fromElf(const std::vector<uint8_t>& file, std::string& error);

    ElfPayload() = default;
    /// A payload given directly (tests, and images not made from an ELF file).
    ElfPayload(std::vector<uint8_t> bytes, uint32_t loadAddress, uint32_t memorySize, uint32_t entry)
        : bytes_(std::move(bytes)), loadAddress_(loadAddress), memorySize_(memorySize), entry_(entry)
    {
    }

    const std::vector<uint8_t>& bytes() const { return bytes_; }
    uint32_t loadAddress() const { return loadAddress_; }
    uint32_t memorySize() const { return memorySize_; }
    uint32_t entry() const { return entry_; }

private:
    std::vector<uint8_t> bytes_;
    uint32_t loadAddress_ = 0;
    uint32_t memorySize_ = 0;
    uint32_t entry_ = 0;
};

} // namespace hostimage
