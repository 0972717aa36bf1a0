#include <arch_x86/Gdt.hpp>

namespace arch_x86 {

namespace {

// A segment descriptor (Intel SDM Vol. 3, 3.4.5), built from its fields.
constexpr uint64_t descriptor(uint32_t base, uint32_t limit, uint8_t access, uint8_t flags)
{
    return (static_cast<uint64_t>(limit) & 0xFFFFu) | ((static_cast<uint64_t>(base) & 0xFFFFFFu) << 16) |
           (static_cast<uint64_t>(access) << 40) | ((static_cast<uint64_t>(limit >> 16) & 0xFu) << 48) |
           (static_cast<uint64_t>(flags & 0xFu) << 52) | ((static_cast<uint64_t>(base >> 24) & 0xFFu) << 56);
}

// Access byte bits (SDM Vol. 3, 3.4.5): present, DPL 0, code/data type.
constexpr uint8_t accessPresent = 0x80;
constexpr uint8_t accessCodeOrData = 0x10;
constexpr uint8_t typeExecuteRead = 0x0A;
constexpr uint8_t typeReadWrite = 0x02;
// Flags nibble: G (4 KiB granularity) and D/B (32-bit segment).
constexpr uint8_t flagsGranularity4k32Bit = 0xC;
// System descriptor type of an available 32-bit TSS (SDM Vol. 3, 3.5,
// Table 3-2); the processor turns it into busy (0xB) while the task runs.
constexpr uint8_t typeTss32Available = 0x9;

// Writable: the processor sets the busy bit of a TSS descriptor on LTR and
// on every task switch into it (SDM Vol. 3, 7.2.2).
alignas(8) constinit uint64_t table[] = {
    0, // The null descriptor.
    descriptor(0, 0xFFFFF, accessPresent | accessCodeOrData | typeExecuteRead, flagsGranularity4k32Bit),
    descriptor(0, 0xFFFFF, accessPresent | accessCodeOrData | typeReadWrite, flagsGranularity4k32Bit),
    0, // Gdt::mainTss, filled by setTaskStateSegment().
    0, // Gdt::pageFaultTss
    0, // Gdt::doubleFaultTss
};

struct [[gnu::packed]] TablePointer {
    uint16_t limit;
    uint32_t base;
};

} // namespace

void Gdt::setTaskStateSegment(uint16_t selector, uint32_t base, uint32_t limit)
{
    table[selector >> 3] = descriptor(base, limit, accessPresent | typeTss32Available, 0);
}

void Gdt::install()
{
    const TablePointer pointer{sizeof table - 1, static_cast<uint32_t>(reinterpret_cast<uintptr_t>(table))};
    asm volatile(
        "lgdt %0\n\t"
        "ljmp %1, $1f\n"
        "1:\n\t"
        "movw %w2, %%ds\n\t"
        "movw %w2, %%es\n\t"
        "movw %w2, %%fs\n\t"
        "movw %w2, %%gs\n\t"
        "movw %w2, %%ss\n\t"
        :
        : "m"(pointer), "i"(kernelCode), "r"(static_cast<uint32_t>(kernelData))
        : "memory");
}

} // namespace arch_x86
