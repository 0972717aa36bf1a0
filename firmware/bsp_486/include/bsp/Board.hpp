// The board support interface the kernel is written against.
//
// Every board support package (bsp_486, bsp_p5smp) provides this same header
// with the same functions, so the kernel and drivers compile unchanged for
// either board. Interrupt lines are numbered per board (here the PC/AT IRQ
// numbers); the kernel only passes the numbers through.
#pragma once

#include <stdint.h>

#include <arch_x86/PortIo.hpp>
#include <boot/BootInfo.hpp>
// nanosecondsIntoTick() and tickTimerDivisor, the time since the last tick:
// each board has its own tick timer and its own copy of this header.
#include <bsp/BoardTick.hpp>
#include <bsp/Uart16550.hpp>
#include <dcos/DateTime.hpp>
#include <dcos/Status.hpp>
#include <runtime/Format.hpp>

namespace bsp {

/// What the board is, for the version report.
struct BoardIdentity {
    const char* name;
    const char* processor;
};

const BoardIdentity& identity();

/// Number of interrupt lines the board's interrupt controller serves.
constexpr unsigned interruptLineCount = 16;
/// The line of the system tick timer.
constexpr unsigned systemTickLine = 0;
/// The line of the console UART.
constexpr unsigned consoleLine = 4;

/// The line of the RS-485 port's UART (COM2).
constexpr unsigned rs485Line = 3;
/// The RS-485 port's UART: its I/O address, for messages.
constexpr uint16_t rs485PortAddress = 0x2F8;

/// The line of the second RS-485 port's UART (COM3). A PC/AT puts COM3 on
/// IRQ 4 with COM1, but the console owns IRQ 4 alone here, and IRQ 7 is
/// the parallel port's: the board routes COM3 to IRQ 9, free on the slave
/// controller (the I/O board has 5, the CAN card 10 and 11).
constexpr unsigned secondRs485Line = 9;
/// The second RS-485 port's UART: its I/O address.
constexpr uint16_t secondRs485PortAddress = 0x3E8;

/// The default system tick rate; "tick_hz=N" on the command line changes it.
constexpr uint32_t defaultTickRateHz = 1000;
/// The tick rates the board's timer makes, in Hz (the 8254's limits).
constexpr uint32_t minimumTickRateHz = 19;
constexpr uint32_t maximumTickRateHz = 10000;
/// The console's line settings: 115200 baud, 8 data bits, no parity, 1 stop bit.
constexpr uint32_t consoleBaud = 115200;

/// Brings up the interrupt controller, the console and the tick timer, in
/// that order, with every interrupt line masked except those attached.
/// Interrupts stay disabled in the CPU; the kernel enables them. The tick
/// runs at @p tickRateHz (the linked application's rate, or the default)
/// unless the command line says tick_hz=. "crystal_ppm=N" (0 to 1000) makes
/// the tick timer model a crystal N ppm fast, for the global time base's
/// tests: an emulated board's clock is otherwise exact.
void initialise(const boot::BootInfo& bootInfo, uint32_t tickRateHz = defaultTickRateHz);

/// Called with interrupts disabled for each interrupt on a line.
using InterruptHandler = void (*)(void* context);

/// Attaches handler to line and unmasks it. Fails with InvalidArgument for
/// a line the board does not have and Busy when a handler is attached.
dcos::Status attachInterrupt(unsigned line, InterruptHandler handler, void* context);

/// Detaches the handler of line and masks it.
dcos::Status detachInterrupt(unsigned line);

void maskInterrupt(unsigned line);
void unmaskInterrupt(unsigned line);
bool isInterruptMasked(unsigned line);

/// True when the interrupt controller holds a request on line (IRR).
bool isInterruptRequested(unsigned line);

/// The lines that cannot interrupt now, one bit per line, read from the
/// interrupt controller itself: masked for lack of a handler, by
/// maskInterrupt(), or by the running task's interrupt level
/// (setTaskInterruptLevel()). For tests and diagnostics.
uint16_t interruptLinesHeldOff();

/// Finds the interrupt whose delivery a fault cut short: called with no
/// handler running, a line the interrupt controller still has in service
/// was acknowledged by the processor, whose push of the interrupt frame then
/// faulted (a task's stack ran into its guard page just then). Sets line to
/// it and returns true, so the kernel can deliver it after all; without that
/// the controller would hold back this line and every less urgent one for good.
bool interruptCutShort(unsigned& line);

/// Reads the board's battery-backed real-time clock, so the time of day is
/// right from power-on. Corrupted when the clock was never set.
dcos::Result<dcos::DateTime> readRealTimeClock();

/// Two lines this node owns that no driver claims at boot (@p which 0 or
/// 1), for on-target tests that run routines in interrupt context, raised
/// by software interrupts on their vectors: 5 and 11 on the ISA board and on
/// node 2 of the dual-Pentium board, 12 and 13 on its node 3.
unsigned spareInterruptLine(unsigned which);

/// Whether this node owns a PCI bus (configuration mechanism #1) whose
/// devices are its own to probe and drive: false on the ISA board, which
/// has none, and on node 3 of the dual-Pentium board, which leaves the bus
/// to node 2 (seed 5.3: node 3 reaches the world only through node 2).
bool ownsPciBus();

/// Makes interrupt line @p line carry interrupt pin @p pin (0 for INTA#
/// to 3 for INTD#) of PCI device @p device on bus @p bus, as the board's
/// interrupt routing says that pin arrives: level triggered, active low,
/// wherever the MP table puts it. @p line is the Interrupt Line the BIOS
/// wrote in the device's configuration header. Call before attaching the
/// line. NotSupported on a node that does not own a PCI bus; NotFound when
/// the board's tables route the pin nowhere; InvalidArgument for a line
/// this node cannot take (another node's, the tick's, line 2) and Busy
/// while a handler is attached to it.
dcos::Status routePciInterrupt(uint8_t bus, uint8_t device, uint8_t pin, unsigned line);

/// Interrupts that arrived on a line with no handler (and were masked).
uint32_t unexpectedInterruptCount(unsigned line);

/// Spurious interrupts reported by the interrupt controller.
uint32_t spuriousInterruptCount();

/// The tick rate in force and the tick's exact period.
uint32_t tickRateHz();
uint64_t tickPeriodNanoseconds();

/// Number of interrupt levels (seed 7.3.3). Level 0 is the system tick, which
/// cannot be masked; a larger number is a lower priority.
constexpr unsigned interruptLevelCount = 15;

/// The interrupt level of a line.
uint8_t interruptLevelOf(unsigned line);

/// Holds off every line of the given level or below it in priority (a
/// larger level number), on top of the lines masked for lack of a handler.
/// 0xFF masks nothing. Applied at every task switch.
void setTaskInterruptLevel(uint8_t level);

/// This controller's node id (16 bits, never 0 or 0xFFFF), from "node=N"
/// on the command line, 1 by default.
uint16_t nodeId();

/// The console: output (waits while its buffer is full) and input.
runtime::CharacterSink& console();

/// Sends a copy of every character written to console() to @p tap too, or
/// (null) to nobody. The tap is called from whatever context writes, an
/// interrupt handler included, before the character is queued for the
/// UART: it must not block and must guard its own state. The system
/// engineering interface agent's monitoring stream sets it while a host
/// follows the console (docs/protocols/monitor.md).
void setConsoleTap(runtime::CharacterSink* tap);
bool consoleRead(char& character);
bool consoleHasInput();

/// Waits until everything queued for the console has left the UART.
void consoleFlush();

/// The board's RS-485 port: COM2, a 16550 whose RTS drives the
/// transceiver's driver enable (half duplex). The board leaves it
/// uninitialised and its line unattached: its user (the Modbus line,
/// drivers/modbus) initialises it with DriverEnable::Rts settings and
/// attaches rs485Line when it brings the line up.
Uart16550& rs485Uart();

/// The board's second RS-485 port: COM3, the same chip core and wiring as
/// COM2 (driver enable on RTS), left to its user the same way; the Modbus
/// line that polls the application's slaves (drivers/modbus) brings it up
/// and attaches secondRs485Line.
Uart16550& secondRs485Uart();

/// Called from the console interrupt after bytes arrive, so a task can
/// sleep until there is input instead of polling.
void setConsoleInputNotifier(InterruptHandler notifier, void* context);

} // namespace bsp
