// The PC/AT peripherals both boards carry at the same addresses: the console
// on COM1, the two RS-485 ports on COM2 and COM3, the CMOS real-time clock,
// and the command-line options every board reads.
//
// Board.hpp declares what the kernel calls (console(), rs485Uart(),
// readRealTimeClock(), ...); PcPeripherals.cpp defines those for both
// boards. This header is the part each board's own file needs: bringing
// the console up on its interrupt line and reading the options that shape
// its tick.
#pragma once

#include <stdint.h>

#include <boot/BootInfo.hpp>
#include <bsp/Uart16550.hpp>

namespace bsp::pc {

/// The console's UART (COM1), for a board's own messages at boot.
Uart16550& consoleUart();

/// Brings the console up at consoleBaud and attaches its interrupt line;
/// panics when the UART does not answer (nothing could be reported then).
/// The console is COM1 on consoleLine unless a board node has its own
/// (@p port, @p line): the dual-Pentium board's node 3.
void initialiseConsole(uint16_t port = 0x3F8, unsigned line = 4);

/// Leaves the CMOS real-time clock to another node of the board: its index
/// and data ports are one pair that two processors cannot share without a
/// lock, so only one node reads it, and readRealTimeClock() answers
/// NotSupported on the others.
void leaveRealTimeClock();

/// The lines held off by a task at interrupt @p level: every line of that
/// level or a lower priority (a larger number), never the tick (level 0)
/// nor a line without a level. Both boards order their lines as the PC/AT's
/// 8259A pair does in fully nested mode (interruptLevelOf()).
uint16_t linesAtOrBelowLevel(uint8_t level);

/// A decimal option of at most @p digits digits (so that it cannot
/// overflow); false when it is empty or has anything else.
bool decimalOption(const char* text, unsigned digits, uint32_t& value);

/// "node=N" on the command line, or @p defaultNode; a value that is not a
/// node id is reported on the console and @p defaultNode kept.
uint16_t nodeFromCommandLine(const boot::BootInfo& bootInfo, uint16_t defaultNode);

/// The tick rate: "tick_hz=N" when it names a rate from minimumTickRateHz to
/// maximumTickRateHz, else @p requested (the application's rate), itself
/// replaced by defaultTickRateHz when it is out of that range. A bad option
/// is reported on the console.
uint32_t tickRateFromCommandLine(const boot::BootInfo& bootInfo, uint32_t requested);

/// "crystal_ppm=N" (0 to 1000): the lab's model of a crystal N parts per
/// million fast, for the global time base's tests (docs/protocols/time.md).
/// An emulated timer counts at exactly its nominal rate, so the model makes
/// the tick timer count fewer per tick than the @p countsPerTick the kernel
/// believes: the tick comes early and the clock gains. Returns the counts
/// to take off, the nearest to N ppm, and says on the console what that gives.
uint32_t crystalShortening(const boot::BootInfo& bootInfo, uint32_t countsPerTick);

} // namespace bsp::pc
