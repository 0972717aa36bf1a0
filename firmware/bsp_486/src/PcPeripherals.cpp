// The PC/AT peripherals both boards share (PcPeripherals.hpp): the serial
// ports at their PC/AT addresses, the CMOS clock, and the options read from
// the kernel command line.
#include <bsp/Board.hpp>
#include <bsp/PcPeripherals.hpp>
#include <bsp/Rtc146818.hpp>
#include <bsp/Uart16550.hpp>

#include <boot/Panic.hpp>

namespace bsp {

namespace {

constexpr uint16_t com1Port = 0x3F8;
// COM2: the same chip core as the console, with the RS-485 port's settings
// given by its user when the line comes up (bsp::rs485Uart()).
static_assert(rs485PortAddress == 0x2F8 && rs485Line == 3, "COM2 is at 0x2F8, IRQ 3 on a PC/AT");
// COM3: the same again, on its own line (see secondRs485Line).
static_assert(secondRs485PortAddress == 0x3E8, "COM3 is at 0x3E8 on a PC/AT");

// The PC/AT's CMOS real-time clock: index port 0x70, data port 0x71.
constexpr uint16_t rtcPort = 0x70;
const Rtc146818 rtc(arch_x86::IoWindow::ports(rtcPort, 2));
Uart16550 uart(arch_x86::IoWindow::ports(com1Port, 8));
Uart16550 rs485(arch_x86::IoWindow::ports(rs485PortAddress, 8));
Uart16550 secondRs485(arch_x86::IoWindow::ports(secondRs485PortAddress, 8));

// The console as every caller sees it: COM1, and a copy to a tap when one
// is set (the monitoring stream's ring, setConsoleTap). The tap pointer is
// read once per character, an aligned word, so setting it needs no lock.
runtime::CharacterSink* volatile consoleTap = nullptr;

class TeeConsole final : public runtime::CharacterSink {
public:
    void put(char character) override
    {
        // The tap first: it never blocks, while the UART may wait for room.
        runtime::CharacterSink* const tap = consoleTap;
        if (tap != nullptr) {
            tap->put(character);
        }
        uart.put(character);
    }
};

TeeConsole teeConsole;
bool realTimeClockOwned = true;

// Writes straight to the UART, for the panic path.
class PolledConsole final : public runtime::CharacterSink {
public:
    void put(char character) override { uart.putPolled(character); }
};

PolledConsole polledConsole;

void consoleInterrupt(void*) { uart.handleInterrupt(); }

// Interrupt level of each line: the 8259A pair's fixed priority order in
// fully nested mode, IRQ 0, 1, then the slave's 8-15 (through IR2), then 3-7.
// Line 2 (the cascade on the ISA board, the other node's interrupts on the
// dual-Pentium board) has no level of its own.
constexpr uint8_t levelOfLine[interruptLineCount] = {0, 1, 0xFF, 10, 11, 12, 13, 14, 2, 3, 4, 5, 6, 7, 8, 9};

} // namespace

namespace pc {

bool decimalOption(const char* text, unsigned digits, uint32_t& value)
{
    value = 0;
    if (text[0] == '\0') {
        return false;
    }
    for (const char* p = text; *p != '\0'; ++p) {
        if (static_cast<unsigned>(p - text) >= digits || *p < '0' || *p > '9') {
            return false;
        }
        value = value * 10 + static_cast<uint32_t>(*p - '0');
    }
    return true;
}

uint16_t linesAtOrBelowLevel(uint8_t level)
{
    uint16_t lines = 0;
    for (unsigned line = 0; line < interruptLineCount; ++line) {
        const uint8_t lineLevel = levelOfLine[line];
        if (lineLevel != 0 && lineLevel != 0xFF && lineLevel >= level) {
            lines = static_cast<uint16_t>(lines | (1u << line));
        }
    }
    return lines;
}

Uart16550& consoleUart() { return uart; }

static_assert(consoleLine == 4, "PcPeripherals.hpp's default console line");

void initialiseConsole(uint16_t port, unsigned line)
{
    if (port != com1Port) {
        uart = Uart16550(arch_x86::IoWindow::ports(port, 8));
    }
    if (uart.initialise(consoleBaud) != dcos::Status::Ok) {
        // No console means no way to report anything; the panic path still
        // tries the polled port in case the chip merely failed the probe.
        dcosPanic("console UART not found at port 0x%x", unsigned(port));
    }
    if (attachInterrupt(line, consoleInterrupt, nullptr) != dcos::Status::Ok) {
        dcosPanic("cannot attach the console's interrupt line %u", line);
    }
}

void leaveRealTimeClock() { realTimeClockOwned = false; }

uint16_t nodeFromCommandLine(const boot::BootInfo& bootInfo, uint16_t defaultNode)
{
    char text[8];
    uint16_t node = defaultNode;
    if (boot::findCommandLineOption(bootInfo.commandLine, "node", text, sizeof text) &&
        !boot::parseNodeId(text, node)) {
        runtime::format(uart, "warning: node=%s is not a node id from 1 to 65534; using %u\r\n", text,
                        unsigned(defaultNode));
        node = defaultNode;
    }
    return node;
}

uint32_t tickRateFromCommandLine(const boot::BootInfo& bootInfo, uint32_t requested)
{
    // An application's tick rate is checked when it is compiled; an
    // impossible one still falls back to the default rather than stop the node.
    if (requested < minimumTickRateHz || requested > maximumTickRateHz) {
        requested = defaultTickRateHz;
    }
    char text[12];
    if (!boot::findCommandLineOption(bootInfo.commandLine, "tick_hz", text, sizeof text)) {
        return requested;
    }
    uint32_t rate = 0;
    if (decimalOption(text, 5, rate) && rate >= minimumTickRateHz && rate <= maximumTickRateHz) {
        return rate;
    }
    runtime::format(uart, "warning: tick_hz=%s is not a rate from %lu to %lu Hz; using %lu Hz\r\n", text,
                    static_cast<unsigned long>(minimumTickRateHz), static_cast<unsigned long>(maximumTickRateHz),
                    static_cast<unsigned long>(requested));
    return requested;
}

uint32_t crystalShortening(const boot::BootInfo& bootInfo, uint32_t countsPerTick)
{
    char text[8];
    if (!boot::findCommandLineOption(bootInfo.commandLine, "crystal_ppm", text, sizeof text)) {
        return 0;
    }
    uint32_t ppm = 0;
    if (!decimalOption(text, 4, ppm) || ppm > 1000) {
        runtime::format(uart, "warning: crystal_ppm=%s is not from 0 to 1000; the crystal is exact\r\n", text);
        return 0;
    }
    // n / (n - k) - 1 = ppm / 1e6, so k = n * ppm / (1e6 + ppm), rounded.
    const uint64_t n = countsPerTick;
    const uint32_t shortenBy = static_cast<uint32_t>((n * ppm + (1'000'000 + ppm) / 2) / (1'000'000 + ppm));
    // The rate that gives, in tenths of a ppm: 1e7 * k / (n - k).
    const uint32_t tenths =
        static_cast<uint32_t>((uint64_t{10'000'000} * shortenBy + (n - shortenBy) / 2) / (n - shortenBy));
    runtime::format(uart, "crystal model: the tick timer counts %lu of %lu, the clock runs %lu.%lu ppm fast\r\n",
                    static_cast<unsigned long>(n - shortenBy), static_cast<unsigned long>(n),
                    static_cast<unsigned long>(tenths / 10), static_cast<unsigned long>(tenths % 10));
    return shortenBy;
}

} // namespace pc

uint8_t interruptLevelOf(unsigned line) { return line < interruptLineCount ? levelOfLine[line] : 0xFF; }

dcos::Result<dcos::DateTime> readRealTimeClock()
{
    if (!realTimeClockOwned) {
        return dcos::Status::NotSupported; // Another node of the board reads it (leaveRealTimeClock()).
    }
    return rtc.read();
}

runtime::CharacterSink& console() { return teeConsole; }

void setConsoleTap(runtime::CharacterSink* tap) { consoleTap = tap; }

bool consoleRead(char& character) { return uart.read(character); }

bool consoleHasInput() { return uart.hasInput(); }

void consoleFlush() { uart.flush(); }

Uart16550& rs485Uart() { return rs485; }

Uart16550& secondRs485Uart() { return secondRs485; }

void setConsoleInputNotifier(InterruptHandler notifier, void* context) { uart.setReceiveNotifier(notifier, context); }

} // namespace bsp

namespace boot {

runtime::CharacterSink& panicConsole() { return bsp::polledConsole; }

} // namespace boot
