// The instruction counter of the counting image (arch_x86/InstructionCounter.hpp).
//
// Linked only into build/486/dcos486-test-counting.elf, the test image the
// remote bench (tests_renode/bench/remote_bench.py) boots on the board's
// benchmark CPU with -icount shift=0, where RDTSC returns the number of
// retired instructions. It defines the weak dcosInstructionCount the kernel
// and the CAN driver call; without this file the symbol is null and they
// count nothing. Like the bench image, this image holds instructions an
// i486 lacks (CPUID, RDTSC) and is exempt from the i486 check; unlike it,
// it still runs on a 486: the counter looks for the time-stamp counter once,
// at boot, and never executes RDTSC on a processor without one.
#include <arch_x86/InstructionCounter.hpp>

#include <stdint.h>

namespace {

// EFLAGS.ID: software can toggle it exactly when the processor has CPUID
// (Intel SDM Vol. 1, 3.4.3.3); a 486DX cannot.
constexpr uint32_t kEflagsId = 1u << 21;
// CPUID leaf 1, EDX: the time-stamp counter and RDTSC (Intel SDM Vol. 2, CPUID).
constexpr uint32_t kCpuidTsc = 1u << 4;

bool hasTimeStampCounter()
{
    uint32_t original;
    uint32_t toggled;
    asm volatile("pushfl\n\t"
                 "popl %0\n\t"
                 "movl %0, %1\n\t"
                 "xorl %2, %1\n\t"
                 "pushl %1\n\t"
                 "popfl\n\t"
                 "pushfl\n\t"
                 "popl %1\n\t"
                 "pushl %0\n\t"
                 "popfl"
                 : "=&r"(original), "=&r"(toggled)
                 : "i"(kEflagsId)
                 : "cc", "memory");
    if (((original ^ toggled) & kEflagsId) == 0) {
        return false;
    }
    uint32_t a, b, c, d;
    asm volatile("cpuid" : "=a"(a), "=b"(b), "=c"(c), "=d"(d) : "a"(0u));
    if (a < 1) {
        return false;
    }
    asm volatile("cpuid" : "=a"(a), "=b"(b), "=c"(c), "=d"(d) : "a"(1u));
    return (d & kCpuidTsc) != 0;
}

// Decided once, before the kernel starts (the image runs its static
// constructors first, firmware/boot/src/MultibootEntry.cpp), so that no
// measured interval ever pays for the test.
bool counting = false;

[[gnu::constructor]] void detectCounter() { counting = hasTimeStampCounter(); }

} // namespace

extern "C" uint64_t dcosInstructionCount()
{
    if (!counting) {
        return 0;
    }
    uint64_t value;
    asm volatile("rdtsc" : "=A"(value)::"memory");
    return value;
}
