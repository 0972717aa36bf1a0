// The instruction counter of a counting image, for the figures of the
// remote bench (docs/performance.md, "Remote transactions").
//
// Under the emulator's -icount shift=0 the time-stamp counter counts retired
// instructions exactly, so two reads of it count the instructions between
// them. The 486 has no time-stamp counter and the production and test
// images must hold only i486 instructions, so the kernel never reads it
// itself: it calls dcosInstructionCount, a weak symbol that only an image
// linked with a counter defines (tests_renode/bench/counter/
// InstructionCounter.cpp, in build/486/dcos486-test-counting.elf). In every
// other image the symbol is null and a read costs a compare and a branch.
#pragma once

#include <stdint.h>

/// The instructions retired since reset, or 0 when the processor has no
/// time-stamp counter. Defined only in a counting image.
extern "C" [[gnu::weak]] uint64_t dcosInstructionCount();

namespace arch_x86 {

/// Whether the image is linked with a counter: a link-time constant, so
/// code that only a counting image needs costs a compare and a branch.
[[gnu::always_inline]] inline bool hasInstructionCounter()
{
#if defined(DCOS_HOST_BUILD)
    return false;
#else
    return dcosInstructionCount != nullptr;
#endif
}

/// The instruction counter, or 0 in an image without one (or on a
/// processor without a time-stamp counter). A difference of two non-zero
/// reads is the number of instructions retired between them where the
/// emulator counts exactly; anywhere else it is a cycle count.
[[gnu::always_inline]] inline uint64_t instructionCount()
{
#if defined(DCOS_HOST_BUILD)
    return 0; // Host unit tests have no counter.
#else
    return hasInstructionCounter() ? dcosInstructionCount() : 0;
#endif
}

} // namespace arch_x86
