// The global descriptor table for flat 32-bit protected mode.
//
// The Multiboot loader leaves a GDT of its own whose location is undefined
// once control passes to the kernel (Multiboot 0.6.96, 3.2), so DCOS loads
// its own before anything else. Besides the flat code and data segments it
// holds the task state segments of the fault tasks (FaultTasks.hpp); the
// processor writes their busy bits, so the table lives in writable memory.
#pragma once

#include <stdint.h>

namespace arch_x86 {

class Gdt {
public:
    /// Segment selectors (index << 3, TI = 0, RPL = 0).
    static constexpr uint16_t kernelCode = 0x08;
    static constexpr uint16_t kernelData = 0x10;
    /// The TSS the kernel and every DCOS task run in.
    static constexpr uint16_t mainTss = 0x18;
    /// The TSS of the page-fault task, entered through a task gate.
    static constexpr uint16_t pageFaultTss = 0x20;
    /// The TSS of the double-fault task, entered through a task gate.
    static constexpr uint16_t doubleFaultTss = 0x28;

    /// Loads the table and reloads every segment register from it.
    static void install();

    /// Fills the descriptor of a 32-bit TSS (SDM Vol. 3, 7.2.2), marked
    /// available. Called before the TSS is loaded or entered.
    static void setTaskStateSegment(uint16_t selector, uint32_t base, uint32_t limit);
};

} // namespace arch_x86
