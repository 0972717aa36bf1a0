// Inline access to the x86 instructions the kernel needs directly.
//
// Everything here exists on the i486; nothing may use an instruction that
// a 486DX lacks (the build checks the image for CPUID-era additions).
#pragma once

#include <stdint.h>

namespace arch_x86 {

/// EFLAGS.IF, the interrupt enable flag (Intel SDM Vol. 3, 2.3).
constexpr uint32_t eflagsInterruptEnable = 1u << 9;

#if defined(DCOS_HOST_BUILD)
// Host unit tests never execute privileged instructions; these keep the
// headers usable in portable code built for the host.
inline void disableInterrupts() {}
inline void enableInterrupts() {}
inline uint32_t readEflags() { return 0; }
inline uint32_t saveFlagsAndDisableInterrupts() { return 0; }
inline void restoreFlags(uint32_t) {}
inline void haltUntilInterrupt() {}
#else
inline void disableInterrupts() { asm volatile("cli" ::: "memory"); }
inline void enableInterrupts() { asm volatile("sti" ::: "memory"); }

inline uint32_t readEflags()
{
    uint32_t flags;
    asm volatile("pushfl; popl %0" : "=r"(flags)::"memory");
    return flags;
}

/// The entry of a critical section: saves EFLAGS and disables interrupts.
/// Sections nest: one entered with interrupts disabled leaves them so.
[[gnu::always_inline]] inline uint32_t saveFlagsAndDisableInterrupts()
{
    uint32_t flags;
    asm volatile("pushfl\n\tpopl %0\n\tcli" : "=r"(flags)::"memory");
    return flags;
}

/// The exit of a critical section: gives EFLAGS back as
/// saveFlagsAndDisableInterrupts() found them, with PUSH and POPF. Two
/// instructions and no branch, where testing the saved IF bit and executing
/// STI took five with the flags spilled around the test; the price on a
/// real i486 is POPF's nine clocks against STI's five. POPF in ring 0
/// restores IF exactly as it was (Intel SDM, POPF), so a section entered
/// with interrupts disabled also leaves them disabled even if it enabled
/// them itself. The other flags it restores are ones a critical section has
/// no business changing: DF is clear on both sides by the ABI, and the
/// kernel never sets TF, AC, NT or IOPL. A memory operand based on ESP is
/// addressed before PUSH moves ESP (Intel SDM, PUSH), so whatever operand
/// the compiler picks is read right.
[[gnu::always_inline]] inline void restoreFlags(uint32_t savedFlags)
{
    asm volatile("pushl %0\n\tpopfl" ::"g"(savedFlags) : "memory", "cc");
}

/// Enables interrupts and halts in one step. STI delays interrupt
/// recognition by one instruction, so no interrupt can slip in between the
/// caller's last check (made with interrupts disabled) and the HLT, which
/// would otherwise sleep through the very event being waited for.
inline void enableInterruptsAndHalt() { asm volatile("sti; hlt" ::: "memory"); }

/// Halts until the next interrupt with the interrupt flag unchanged.
inline void haltUntilInterrupt() { asm volatile("hlt" ::: "memory"); }

inline uint32_t readCr0()
{
    uint32_t value;
    asm volatile("movl %%cr0, %0" : "=r"(value));
    return value;
}

inline uint32_t readCr2()
{
    uint32_t value;
    asm volatile("movl %%cr2, %0" : "=r"(value));
    return value;
}

inline uint32_t readCr3()
{
    uint32_t value;
    asm volatile("movl %%cr3, %0" : "=r"(value));
    return value;
}
#endif

/// Disables interrupts for its lifetime and restores the previous state,
/// so critical sections nest correctly inside interrupt handlers: the scoped
/// form of saveFlagsAndDisableInterrupts() and restoreFlags().
class InterruptGuard {
public:
    [[gnu::always_inline]] InterruptGuard() : savedFlags_(saveFlagsAndDisableInterrupts()) {}
    [[gnu::always_inline]] ~InterruptGuard() { restoreFlags(savedFlags_); }
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;

private:
    uint32_t savedFlags_;
};

} // namespace arch_x86
