// The time since the last tick on the ISA i486 board: its tick is the
// 8254's counter 0, whose request shows on the master 8259A.
//
// Board.hpp includes this header; the dual-Pentium board has its own
// (firmware/bsp_p5smp/include/bsp/BoardTick.hpp), found first on its
// include path, with the same two names.
#pragma once

#include <stdint.h>

#include <arch_x86/PortIo.hpp>

namespace bsp {

/// The divisor programmed into the tick timer (the 8254's counter 0), 0
/// until the tick starts. Only nanosecondsIntoTick reads it.
extern uint32_t tickTimerDivisor;

/// Nanoseconds elapsed since the last tick, read from the tick timer, for
/// time measurements finer than a tick. Call with interrupts disabled.
///
/// Inline and with raw port instructions, not through the chip drivers'
/// checked I/O windows: it is on the path of GetSystemClock and Uptime, and
/// the call and the windows cost it about 70 instructions. It reads what
/// Pit8254::readCount and Pic8259::readRequestRegister read, the latter on
/// the master only, where the tick's line is.
inline uint32_t nanosecondsIntoTick()
{
    // The 8254's counter 0 and control port and the master 8259's command
    // port on a PC/AT (Board486.cpp).
    constexpr uint16_t counter0Port = 0x40;
    constexpr uint16_t controlPort = 0x43;
    constexpr uint16_t masterPicCommandPort = 0x20;
    constexpr uint8_t latchCounter0 = 0x00;
    constexpr uint8_t ocw3ReadRequestRegister = 0x0A;
    // 1e9 / 1193182 Hz is 838.0958 ns per count; scaled by 64 it is 53,638,
    // and since that is even, elapsed * 53638 >> 6 is exactly
    // elapsed * 26819 >> 5, whose product fits 32 bits for any elapsed count
    // (at most 1.5 times the 16-bit divisor): one IMUL, not a 64-bit MUL.
    constexpr uint32_t nanosecondsPerCountTimes32 = 26819;
    static_assert(uint64_t{0xFFFF} * 3 / 2 * nanosecondsPerCountTimes32 <= 0xFFFFFFFFu, "the product fits 32 bits");
    // The tick is IRQ 0 (Board486.cpp checks systemTickLine): bit 0 of the master's request register.

    const uint32_t divisor = tickTimerDivisor;
#if defined(DCOS_HOST_BUILD)
    arch_x86::portWrite8(controlPort, latchCounter0);
    const uint32_t low = arch_x86::portRead8(counter0Port);
    const uint32_t high = arch_x86::portRead8(counter0Port);
    const uint32_t count = low | (high << 8);
#else
    // The latch and the two reads, low byte first, with the bytes put
    // together in AX as they arrive; EAX starts at zero, which is also the
    // latch command, so the count needs no masking.
    static_assert(latchCounter0 == 0, "EAX holds the latch command");
    uint32_t count;
    asm volatile("outb %%al, %[control]\n\t"
                 "inb %[counter], %%al\n\t"
                 "movb %%al, %%ah\n\t"
                 "inb %[counter], %%al\n\t"
                 "xchgb %%al, %%ah"
                 : "=a"(count)
                 : "0"(0u), [control] "N"(controlPort), [counter] "N"(counter0Port)
                 : "memory");
#endif
    // Before the tick starts the divisor is 0 and so is the result.
    uint32_t elapsed = count <= divisor ? divisor - count : 0;
    // A tick that has happened but is not serviced yet (interrupts are off)
    // shows as a request: the count has already started the next period.
    // The count reads the divisor itself only during the first count after
    // the reload, too soon for the tick's handler to have run: that period
    // is not counted yet either, request or not. QEMU's 8254 raises its
    // output one count after the reload, so there a read in that window
    // sees no request, and the uptime would be a whole tick short.
    arch_x86::portWrite8(masterPicCommandPort, ocw3ReadRequestRegister);
    const bool tickRequested = (arch_x86::portRead8(masterPicCommandPort) & 1u) != 0;
    if ((tickRequested || (count == divisor && divisor != 0)) && elapsed < divisor / 2u) {
        elapsed += divisor;
    }
#if defined(DCOS_HOST_BUILD)
    return (elapsed * nanosecondsPerCountTimes32) >> 5;
#else
    // One IMUL: tuned for the i486, GCC spells a multiplication by a
    // constant as ten shifts, adds and LEAs, which are fewer cycles there
    // but three times the instructions.
    uint32_t product;
    asm("imull %[factor], %[elapsed], %[product]"
        : [product] "=r"(product)
        : [elapsed] "rm"(elapsed), [factor] "i"(nanosecondsPerCountTimes32)
        : "cc");
    return product >> 5;
#endif
}

} // namespace bsp
