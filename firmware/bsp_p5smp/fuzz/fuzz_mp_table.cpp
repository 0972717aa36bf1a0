// Fuzz target: the reader of the BIOS's MultiProcessor Specification tables
// (bsp::findMpConfiguration, bsp::parseMpConfiguration), which the
// dual-Pentium board believes about its processors and interrupt wiring.
//
// The input is a PC's low memory, sparse: its first two little-endian words
// are the BIOS data area's EBDA segment (0x40E) and base memory size in KiB
// (0x413); the rest is the BIOS ROM from 0xF0000 (at most 64 KiB), which
// also shows at the EBDA and at the last KiB of base memory, so that every
// search area sees tables. Nothing else is readable: a read that leaves
// those regions fails, as it would on a board without that memory, and
// AddressSanitizer stops any that the parser does not check. The floating
// pointer is looked for at the start of the ROM and then by the search.
// Checks: whatever the input, every count stays within its room; a table
// accepted has exactly one enabled bootstrap processor and an enabled I/O
// APIC, its routes resolve to an I/O APIC pin, and the search and a parse
// at the pointer the search found agree.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <bsp/MpTable.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace {

constexpr uint32_t kBiosRom = 0xF0000;
constexpr uint32_t kBiosRomBytes = 0x10000;
constexpr uint32_t kBdaStart = 0x400;
constexpr uint32_t kBdaBytes = 0x100;

class SparseMemory final : public bsp::PhysicalMemory {
public:
    SparseMemory(const uint8_t* data, size_t size)
    {
        bda_.assign(kBdaBytes, 0);
        for (size_t i = 0; i < 4 && i < size; ++i) {
            bda_[0x0E + i + (i >= 2 ? 3 : 0)] = data[i]; // 0x40E-0x40F, then 0x413-0x414
        }
        const uint8_t* rom = data + (size > 4 ? 4 : size);
        const size_t romBytes = size > 4 ? size - 4 : 0;
        rom_.assign(rom, rom + (romBytes < kBiosRomBytes ? romBytes : kBiosRomBytes));
        const uint32_t ebda = uint32_t(bda_[0x0E] | (bda_[0x0F] << 8)) << 4;
        const uint32_t kib = bda_[0x13] | (bda_[0x14] << 8);
        regions_[0] = {kBdaStart, &bda_};
        regions_[1] = {kBiosRom, &rom_};
        regions_[2] = {ebda, &rom_};
        regions_[3] = {kib >= 1 ? (kib - 1) * 1024 : 0, &rom_};
    }

    bool read(uint32_t address, void* into, uint32_t bytes) const override
    {
        for (const Region& region : regions_) {
            const uint64_t end = uint64_t{address} + bytes;
            if (address >= region.start && end <= uint64_t{region.start} + region.bytes->size()) {
                std::memcpy(into, region.bytes->data() + (address - region.start), bytes);
                return true;
            }
        }
        return false;
    }

private:
    struct Region {
        uint32_t start = 0;
        const std::vector<uint8_t>* bytes = nullptr;
    };
    std::vector<uint8_t> bda_;
    std::vector<uint8_t> rom_;
    Region regions_[4];
};

void checkBounds(const bsp::MpConfiguration& c)
{
    FUZZ_CHECK(c.processorCount <= bsp::MpConfiguration::kMaximumProcessors);
    FUZZ_CHECK(c.busCount <= bsp::MpConfiguration::kMaximumBuses);
    FUZZ_CHECK(c.ioApicCount <= bsp::MpConfiguration::kMaximumIoApics);
    FUZZ_CHECK(c.interruptCount <= bsp::MpConfiguration::kMaximumInterrupts);
    FUZZ_CHECK(c.localInterruptCount <= bsp::MpConfiguration::kMaximumLocalInterrupts);
    FUZZ_CHECK(c.oemId[8] == '\0' && c.productId[12] == '\0');
}

void checkAccepted(const bsp::MpConfiguration& c)
{
    const bsp::MpProcessor* bootstrap = c.bootstrapProcessor();
    FUZZ_CHECK(bootstrap != nullptr && bootstrap->enabled && bootstrap->bootstrap);
    bool enabledIoApic = false;
    for (unsigned i = 0; i < c.ioApicCount; ++i) {
        enabledIoApic = enabledIoApic || c.ioApics[i].enabled;
        FUZZ_CHECK(c.ioApic(c.ioApics[i].id) != nullptr);
    }
    FUZZ_CHECK(enabledIoApic);
    FUZZ_CHECK(c.specRevision == 1 || c.specRevision == 4);
    for (unsigned i = 0; i < c.interruptCount; ++i) {
        FUZZ_CHECK(c.interrupts[i].type <= bsp::MpConfiguration::kInterruptExtInt);
    }
    bsp::IoApicRoute route{};
    for (unsigned irq = 0; irq < 256; ++irq) {
        if (c.isaRoute(uint8_t(irq), route)) {
            // A route names the one I/O APIC the entry named, or the first for "all".
            FUZZ_CHECK(route.ioApicId != bsp::MpConfiguration::kAllApics || c.ioApics[0].id == route.ioApicId);
        }
    }
    for (unsigned i = 0; i < c.busCount; ++i) {
        // A table may list a bus id twice; the first entry is the one believed.
        const bsp::MpBus* bus = c.bus(c.buses[i].id);
        FUZZ_CHECK(bus != nullptr && bus <= &c.buses[i]);
        for (unsigned device = 0; device < 33; ++device) {
            for (unsigned pin = 0; pin < 5; ++pin) {
                const bool found = c.pciRoute(bus->id, uint8_t(device), uint8_t(pin), route);
                FUZZ_CHECK(!found || (device < 32 && pin < 4 && bus->kind == bsp::MpBusKind::Pci));
            }
        }
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const SparseMemory memory(data, size);

    bsp::MpConfiguration parsed;
    const bsp::MpResult atRom = bsp::parseMpConfiguration(memory, kBiosRom, parsed);
    FUZZ_CHECK(bsp::mpErrorText(atRom.error) != nullptr);
    checkBounds(parsed);
    if (atRom.error == bsp::MpError::None) {
        FUZZ_CHECK(atRom.address == kBiosRom && parsed.floatingPointerAddress == kBiosRom);
        checkAccepted(parsed);
    }

    bsp::MpConfiguration found;
    const bsp::MpResult searched = bsp::findMpConfiguration(memory, found);
    FUZZ_CHECK(bsp::mpErrorText(searched.error) != nullptr);
    checkBounds(found);
    if (searched.error == bsp::MpError::None) {
        checkAccepted(found);
        bsp::MpConfiguration again;
        const bsp::MpResult reparsed = bsp::parseMpConfiguration(memory, searched.address, again);
        FUZZ_CHECK(reparsed.error == bsp::MpError::None);
        FUZZ_CHECK(again.tableAddress == found.tableAddress);
        FUZZ_CHECK(again.processorCount == found.processorCount && again.interruptCount == found.interruptCount);
        FUZZ_CHECK(std::strcmp(again.oemId, found.oemId) == 0);
    }
    return 0;
}
