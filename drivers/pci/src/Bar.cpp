#include <pci/Bar.hpp>
#include <pci/FunctionConfig.hpp>

namespace pci {

using dcos::Result;
using dcos::Status;

namespace {

// The lowest bit set in @p mask: the size a BAR whose writable address
// bits are @p mask decodes (LB 6.2.5.1). Taking the lowest set bit rather
// than ~mask + 1 also sizes an I/O BAR whose bits 31-16 are hardwired to
// zero, as a device that decodes only 64 KiB of I/O may make them.
constexpr uint64_t lowestBit(uint64_t mask) { return mask & (~mask + 1); }

constexpr uint64_t kFourGiB = uint64_t{1} << 32;

} // namespace

Result<Bar> Bar::probe(const ConfigSpace& config, const Device& device, unsigned index)
{
    if (!device.address.valid() || index >= device.barCount()) {
        return Status::InvalidArgument;
    }
    FunctionConfig function(config, device.address);
    const unsigned offset = reg::kBar0 + index * reg::kBarSize;
    const uint32_t original = function.read32(offset);
    if (function.status() != Status::Ok) {
        return function.status();
    }

    // The kind bits are read-only, so the value as found tells the kind
    // before anything is written.
    Bar bar;
    const bool io = (original & reg::kBarSpaceIo) != 0;
    const uint32_t type = original & reg::kBarMemoryTypeMask;
    if (!io && type != reg::kBarMemoryType32 && type != reg::kBarMemoryTypeBelow1M &&
        type != reg::kBarMemoryType64) {
        return Status::NotSupported; // Type 11 is reserved (LB 6.2.5.1).
    }
    const bool wide = !io && type == reg::kBarMemoryType64;
    if (wide && index + 1 >= device.barCount()) {
        return Status::NotSupported; // Its upper half would be past the last BAR.
    }

    // Sizing: decode off, all ones in, read back, the BAR and then the
    // command register as they were.
    const uint16_t command = function.read16(reg::kCommand);
    function.write16(reg::kCommand, static_cast<uint16_t>(command & ~reg::kCommandDecode));
    function.write32(offset, reg::kBarSizingPattern);
    const uint32_t sized = function.read32(offset);
    function.write32(offset, original);
    uint32_t originalHigh = 0;
    uint32_t sizedHigh = 0;
    if (wide) {
        originalHigh = function.read32(offset + reg::kBarSize);
        function.write32(offset + reg::kBarSize, reg::kBarSizingPattern);
        sizedHigh = function.read32(offset + reg::kBarSize);
        function.write32(offset + reg::kBarSize, originalHigh);
    }
    function.write16(reg::kCommand, command);
    if (function.status() != Status::Ok) {
        return function.status();
    }

    if (io) {
        const uint32_t mask = sized & reg::kBarIoAddressMask;
        if (mask == 0) {
            return bar; // Not implemented.
        }
        bar.kind = Kind::Io;
        bar.base = original & reg::kBarIoAddressMask;
        bar.size = static_cast<uint32_t>(lowestBit(mask));
        return bar;
    }

    const uint64_t mask = (uint64_t{sizedHigh} << 32) | (sized & reg::kBarMemoryAddressMask);
    if (mask == 0) {
        bar.registers = wide ? 2 : 1;
        return bar; // Not implemented.
    }
    const uint64_t base = (uint64_t{originalHigh} << 32) | (original & reg::kBarMemoryAddressMask);
    const uint64_t size = lowestBit(mask);
    if (size >= kFourGiB || base >= kFourGiB || base + size > kFourGiB) {
        return Status::NotSupported; // Out of a 32-bit processor's reach.
    }
    bar.kind = wide ? Kind::Memory64 : Kind::Memory32;
    bar.base = static_cast<uint32_t>(base);
    bar.size = static_cast<uint32_t>(size);
    bar.prefetchable = (original & reg::kBarMemoryPrefetchable) != 0;
    bar.registers = wide ? 2 : 1;
    return bar;
}

} // namespace pci
