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
/// so critical sections nest correctly inside interrupt handlers.
class InterruptGuard {
public:
    InterruptGuard() : savedFlags_(readEflags()) { disableInterrupts(); }
    ~InterruptGuard()
    {
        if ((savedFlags_ & eflagsInterruptEnable) != 0) {
            enableInterrupts();
        }
    }
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;

private:
    uint32_t savedFlags_;
};

} // namespace arch_x86
