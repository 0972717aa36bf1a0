// What the dual-Pentium board offers beyond the board interface both boards
// share (bsp/Board.hpp): its MP configuration, its inter-processor interrupt
// line, the calibrated APIC timer, and the routing of PCI interrupts.
#pragma once

#include <stdint.h>

#include <bsp/MpTable.hpp>

namespace bsp {

/// The line the other processor's inter-processor interrupts arrive on: the
/// PC/AT's cascade input, which no ISA device can use.
constexpr unsigned interProcessorLine = 2;

/// The MP configuration the BIOS left, checked; null when none was found or
/// it failed a check (the boot report says why), so the board runs on the
/// MP spec's default configuration with one processor.
const MpConfiguration* mpConfiguration();

/// The local APIC timer's rate at the divider the tick uses, measured
/// against the 8254 at boot.
uint64_t apicTimerFrequencyHz();

/// The line PCI @p bus / @p device's interrupt pin @p pin (0 = INTA# to
/// 3 = INTD#) arrives on, with the line's I/O APIC entry switched to the
/// polarity and trigger the MP table gives that PCI interrupt (low, level
/// for a PCI bus). False when the MP table routes it to no ISA line's pin.
bool pciInterruptLine(uint8_t bus, uint8_t device, uint8_t pin, unsigned& line);

} // namespace bsp
