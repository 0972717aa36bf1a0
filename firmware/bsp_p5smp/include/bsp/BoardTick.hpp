// The time since the last tick on the dual-Pentium board: each node's tick
// is its own local APIC's timer in periodic mode (Intel SDM Vol. 3A,
// 11.5.4), calibrated against the 8254 at boot (BoardP5smp.cpp).
//
// The ISA board's header of the same name reads the 8254 instead; Board.hpp
// includes whichever the board's include path finds first. The variables
// here are named apart from that board's (tickTimerDivisor) so that an
// object compiled against the other header cannot link into this image.
#pragma once

#include <stdint.h>

namespace bsp {

/// The local APIC timer's counts per tick, 0 until the tick starts: the
/// timer counts from apicTickCounts - 1 down to 0 and reloads.
extern uint32_t apicTickCounts;
/// Nanoseconds per count of the local APIC timer, times 2^24, from the calibration.
extern uint32_t apicNanosecondsPerCountQ24;

/// Nanoseconds elapsed since the last tick, read from the local APIC timer,
/// for time measurements finer than a tick. Call with interrupts disabled.
///
/// Inline and with plain loads of the APIC's registers, not through the
/// driver's checked window: it is on the path of GetSystemClock and Uptime.
inline uint32_t nanosecondsIntoTick()
{
#if defined(DCOS_HOST_BUILD)
    return 0;
#else
    // The local APIC's registers at its default base (SDM Vol. 3A, Table
    // 11-1): the timer's current count, and the interrupt request register
    // word of vectors 32-63, whose bit 0 is the tick's vector, 32.
    constexpr uintptr_t currentCountRegister = 0xFEE00390u;
    constexpr uintptr_t requestRegister32To63 = 0xFEE00210u;
    const uint32_t counts = apicTickCounts;
    if (counts == 0) {
        return 0; // The tick has not started.
    }
    const uint32_t count = *reinterpret_cast<const volatile uint32_t*>(currentCountRegister);
    uint32_t elapsed = count < counts ? counts - 1 - count : 0;
    // A tick that has happened but is not serviced yet (interrupts are off)
    // shows as a request: the count has already started the next period.
    const bool tickRequested = (*reinterpret_cast<const volatile uint32_t*>(requestRegister32To63) & 1u) != 0;
    if (tickRequested && elapsed < counts / 2u) {
        elapsed += counts;
    }
    // One MUL of 32 by 32 bits into EDX:EAX; the shift takes the middle.
    return static_cast<uint32_t>((uint64_t{elapsed} * apicNanosecondsPerCountQ24) >> 24);
#endif
}

} // namespace bsp
