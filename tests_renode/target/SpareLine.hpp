// The interrupt line an on-target test borrows to run a routine in
// interrupt context: one its node owns and no driver of the test image
// claims at boot (bsp::spareInterruptLine()), raised by a software
// interrupt on the line's vector.
#pragma once

#include <bsp/Board.hpp>

extern "C" [[noreturn]] void dcosPanic(const char* format, ...);

namespace target_test {

/// The node's first or (@p which = 1) second spare line.
inline unsigned spareLine(unsigned which = 0) { return bsp::spareInterruptLine(which); }

/// Raises a spare line's vector (0x20 + line) as its device would.
inline void raiseSpareLine(unsigned which = 0)
{
    // INT takes its vector as an immediate: one instruction per line a board names.
    switch (spareLine(which)) {
    case 5:
        asm volatile("int $0x25" ::: "memory");
        break;
    case 11:
        asm volatile("int $0x2B" ::: "memory");
        break;
    case 12:
        asm volatile("int $0x2C" ::: "memory");
        break;
    case 13:
        asm volatile("int $0x2D" ::: "memory");
        break;
    default:
        dcosPanic("no software interrupt for spare line %u", spareLine(which));
    }
}

} // namespace target_test
