// The global descriptor table for flat 32-bit protected mode.
//
// The Multiboot loader leaves a GDT of its own whose location is undefined
// once control passes to the kernel (Multiboot 0.6.96, 3.2), so DCOS loads
// its own before anything else.
#pragma once

#include <stdint.h>

namespace arch_x86 {

class Gdt {
public:
    /// Segment selectors (index << 3, TI = 0, RPL = 0).
    static constexpr uint16_t kernelCode = 0x08;
    static constexpr uint16_t kernelData = 0x10;

    /// Loads the table and reloads every segment register from it.
    static void install();
};

} // namespace arch_x86
