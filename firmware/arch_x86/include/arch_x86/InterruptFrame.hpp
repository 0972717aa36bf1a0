// The register image the interrupt entry stubs save on the stack.
//
// The layout mirrors InterruptStubs.S exactly: the stub pushes the segment
// registers after PUSHAL, on top of the vector number and error code it
// pushed itself, which sit on top of what the CPU pushed (Intel SDM Vol. 3,
// 6.12.1: EFLAGS, CS, EIP, and an error code for some exceptions).
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace arch_x86 {

struct InterruptFrame {
    uint32_t gs, fs, es, ds;
    uint32_t edi, esi, ebp, espAtPushal, ebx, edx, ecx, eax;
    uint32_t vector;
    uint32_t errorCode;
    uint32_t eip, cs, eflags;
    // Present only when the interrupt came from a less privileged ring.
    uint32_t userEsp, userSs;

    /// The interrupted code's stack pointer. In ring 0 the CPU pushes no
    /// ESP, so the interrupted stack began right after EFLAGS.
    uint32_t interruptedEsp() const
    {
        return (cs & 3u) != 0 ? userEsp : static_cast<uint32_t>(reinterpret_cast<uintptr_t>(&userEsp));
    }
};

static_assert(offsetof(InterruptFrame, vector) == 48, "InterruptStubs.S pushes 12 words first");
static_assert(offsetof(InterruptFrame, eip) == 56, "the CPU frame follows vector and error code");
static_assert(offsetof(InterruptFrame, cs) == 60, "InterruptStubs.S reads the interrupted CS at 60(%esp)");

/// First vector used for hardware interrupt requests (the PIC is remapped
/// here, above the 32 vectors Intel reserves for exceptions).
constexpr unsigned firstIrqVector = 32;

} // namespace arch_x86
