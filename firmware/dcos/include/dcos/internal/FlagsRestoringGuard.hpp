// An interrupt guard for the memory agents' fast paths (issue 12).
//
// arch_x86::InterruptGuard keeps EFLAGS and, on leaving, tests its IF bit
// and executes STI when it was set: five instructions with the flags
// spilled and reloaded around the test. This guard gives the saved flags
// back with PUSH and POPF instead, two instructions (one when the saved word
// is pushed straight from the frame), and leaves no branch. POPF in ring 0
// restores IF exactly as it was, and every other flag it restores is one
// the guarded code has no business changing (the direction flag is clear
// on both sides by the ABI). The price on a real i486 is POPF's nine clocks
// against STI's five, which the shorter sequence pays back.
//
// It is kept beside the memory agents rather than replacing InterruptGuard,
// which every agent uses; it could move to arch_x86 once the others adopt it.
#pragma once

#include <arch_x86/Cpu.hpp>

#include <stdint.h>

namespace dcos::internal {

/// Disables interrupts for its lifetime and restores the previous EFLAGS on exit.
class FlagsRestoringGuard {
public:
#if defined(DCOS_HOST_BUILD)
    FlagsRestoringGuard() = default;
#else
    [[gnu::always_inline]] FlagsRestoringGuard()
    {
        asm volatile("pushfl\n\tpopl %0\n\tcli" : "=r"(savedFlags_)::"memory");
    }
    // A memory operand based on ESP is addressed before PUSH moves ESP
    // (Intel SDM, PUSH), so any operand the compiler picks is read right.
    [[gnu::always_inline]] ~FlagsRestoringGuard()
    {
        asm volatile("pushl %0\n\tpopfl" ::"g"(savedFlags_) : "memory", "cc");
    }
#endif
    FlagsRestoringGuard(const FlagsRestoringGuard&) = delete;
    FlagsRestoringGuard& operator=(const FlagsRestoringGuard&) = delete;

private:
#if !defined(DCOS_HOST_BUILD)
    uint32_t savedFlags_;
#endif
};

} // namespace dcos::internal
