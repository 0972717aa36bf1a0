// Board support for the ISA i486 single-board controller (seed 9.2,
// controller node 1): an 8259A pair, an 8254, a 16550 on COM1 (the console)
// and a second one on COM2 (the RS-485 port), at their PC/AT addresses.
#include <bsp/Board.hpp>
#include <bsp/Pic8259.hpp>
#include <bsp/Rtc146818.hpp>
#include <bsp/Pit8254.hpp>
#include <bsp/Uart16550.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/Idt.hpp>
#include <arch_x86/PortIo.hpp>
#include <boot/Panic.hpp>

namespace bsp {

namespace {

// PC/AT port assignments.
constexpr uint16_t masterPicPort = 0x20;
constexpr uint16_t slavePicPort = 0xA0;
constexpr uint16_t pitPort = 0x40;
constexpr uint16_t com1Port = 0x3F8;
// COM2: the same chip core as the console, with the RS-485 port's settings
// given by its user when the line comes up (bsp::rs485Uart()).
static_assert(rs485PortAddress == 0x2F8 && rs485Line == 3, "COM2 is at 0x2F8, IRQ 3 on a PC/AT");
// COM3: the same again, on its own line (see secondRs485Line).
static_assert(secondRs485PortAddress == 0x3E8, "COM3 is at 0x3E8 on a PC/AT");

Pic8259 pic(arch_x86::IoWindow::ports(masterPicPort, 2), arch_x86::IoWindow::ports(slavePicPort, 2));
// The PC/AT's CMOS real-time clock: index port 0x70, data port 0x71.
constexpr uint16_t rtcPort = 0x70;
const Rtc146818 rtc(arch_x86::IoWindow::ports(rtcPort, 2));
Pit8254 pit(arch_x86::IoWindow::ports(pitPort, 4));
Uart16550 uart(arch_x86::IoWindow::ports(com1Port, 8));

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
Uart16550 rs485(arch_x86::IoWindow::ports(rs485PortAddress, 8));
Uart16550 secondRs485(arch_x86::IoWindow::ports(secondRs485PortAddress, 8));

struct Attachment {
    InterruptHandler handler;
    void* context;
};

Attachment attachments[interruptLineCount];
// What the dispatch calls straight away: a line's attachment, except on the
// lines that can be spurious (7 and 15, whose in-service bit must be read
// first) and on lines nobody owns, which keep a null handler here. So one
// test of the handler sends every uncommon case to dispatchUncommon(), and
// the common one pays no test of its line number.
Attachment directAttachments[interruptLineCount];

// Whether an interrupt on @p line can be spurious (Pic8259::isGenuine).
constexpr bool canBeSpurious(unsigned line) { return (line & 7u) == 7u; }

void setAttachment(unsigned line, Attachment attachment)
{
    attachments[line] = attachment;
    directAttachments[line] = canBeSpurious(line) ? Attachment{nullptr, nullptr} : attachment;
}
uint32_t unexpected[interruptLineCount];
uint32_t spurious;
uint16_t node = 1;

// Interrupt level of each line: the 8259A pair's fixed priority order in
// fully nested mode, IRQ 0, 1, then the slave's 8-15 (through IR2), then 3-7.
// The cascade line 2 has no level of its own.
constexpr uint8_t levelOfLine[interruptLineCount] = {0, 1, 0xFF, 10, 11, 12, 13, 14, 2, 3, 4, 5, 6, 7, 8, 9};


const BoardIdentity board{"isa486", "i486DX"};

// Writes straight to the UART, for the panic path.
class PolledConsole final : public runtime::CharacterSink {
public:
    void put(char character) override { uart.putPolled(character); }
};

PolledConsole polledConsole;

void consoleInterrupt(void*) { uart.handleInterrupt(); }

// The interrupt controller's vectors are exactly the board's lines, so the
// dispatch needs no range check: Idt calls it for no other vector.
static_assert(arch_x86::Idt::firstTrapVector - arch_x86::firstIrqVector == interruptLineCount,
              "the vectors below the traps are the 8259A pair's lines");

// The attached routine of @p line with interrupts enabled, then the EOI.
[[gnu::always_inline]] inline void runAttachment(const Attachment& attachment, unsigned line)
{
    // The 8259A holds back this line and every less urgent one until the
    // EOI below, so enabling interrupts lets only more urgent lines nest.
    arch_x86::enableInterrupts();
    attachment.handler(attachment.context);
    arch_x86::disableInterrupts();
    pic.endOfInterrupt(line);
}

// Lines 7 and 15, which can be spurious, and lines nobody owns.
[[gnu::noinline]] void dispatchUncommon(unsigned line)
{
    if (!pic.isGenuine(line)) {
        // A spurious IRQ 15 still occupied the master's cascade input.
        if (line == 15) {
            pic.endOfInterrupt(Pic8259::cascadeLine);
        }
        ++spurious;
        return;
    }
    const Attachment& attachment = attachments[line];
    if (attachment.handler != nullptr) {
        runAttachment(attachment, line);
    } else {
        // Nobody owns this line: mask it so it cannot storm, and count it.
        ++unexpected[line];
        pic.mask(line);
        pic.endOfInterrupt(line);
    }
}

void dispatchInterrupt(unsigned line)
{
    const Attachment& direct = directAttachments[line];
    if (direct.handler == nullptr) [[unlikely]] {
        dispatchUncommon(line);
        return;
    }
    runAttachment(direct, line);
}

} // namespace

uint32_t tickTimerDivisor = 0;

const BoardIdentity& identity() { return board; }

namespace {

// "crystal_ppm=N" (0 to 1000): the lab's model of a crystal N parts per
// million fast, for the global time base's tests (docs/protocols/time.md).
// An emulated 8254 counts at exactly its nominal rate, so the model counts
// fewer per tick than the divisor the kernel believes: the tick comes
// early and the clock gains. Returns the counts to take off a divisor of
// @p divisor, the nearest to N ppm, and says what that gives.
uint16_t crystalModel(const boot::BootInfo& bootInfo, uint16_t divisor)
{
    char text[8];
    if (!boot::findCommandLineOption(bootInfo.commandLine, "crystal_ppm", text, sizeof text)) {
        return 0;
    }
    uint32_t ppm = 0;
    bool numeric = text[0] != '\0';
    for (const char* p = text; *p != '\0' && numeric; ++p) {
        numeric = p - text < 4 && *p >= '0' && *p <= '9';
        ppm = ppm * 10 + static_cast<uint32_t>(*p - '0');
    }
    if (!numeric || ppm > 1000) {
        runtime::format(uart, "warning: crystal_ppm=%s is not from 0 to 1000; the crystal is exact\r\n", text);
        return 0;
    }
    // divisor / (divisor - k) - 1 = ppm / 1e6, so k = divisor * ppm / (1e6 + ppm), rounded.
    const uint32_t shortenBy = (divisor * ppm + (1'000'000 + ppm) / 2) / (1'000'000 + ppm);
    // The rate that gives, in tenths of a ppm: 1e7 * k / (divisor - k).
    const uint32_t tenths =
        static_cast<uint32_t>((uint64_t{10'000'000} * shortenBy + (divisor - shortenBy) / 2) / (divisor - shortenBy));
    runtime::format(uart, "crystal model: the tick timer counts %lu of %u, the clock runs %lu.%lu ppm fast\r\n",
                    static_cast<unsigned long>(divisor - shortenBy), unsigned(divisor),
                    static_cast<unsigned long>(tenths / 10), static_cast<unsigned long>(tenths % 10));
    return static_cast<uint16_t>(shortenBy);
}

} // namespace

static_assert(systemTickLine == 0, "BoardTick.hpp reads the tick's request as bit 0 of the master 8259");
static_assert(Pit8254::minimumRateHz == minimumTickRateHz && Pit8254::maximumRateHz == maximumTickRateHz);

void initialise(const boot::BootInfo& bootInfo, uint32_t tickRateHz)
{
    char nodeText[8];
    if (boot::findCommandLineOption(bootInfo.commandLine, "node", nodeText, sizeof nodeText) &&
        !boot::parseNodeId(nodeText, node)) {
        runtime::format(uart, "warning: node=%s is not a node id from 1 to 65534; using 1\r\n", nodeText);
    }
    pic.initialise(static_cast<uint8_t>(arch_x86::firstIrqVector));
    arch_x86::Idt::setInterruptHandler(dispatchInterrupt);

    if (uart.initialise(consoleBaud) != dcos::Status::Ok) {
        // No console means no way to report anything; the panic path still
        // tries the polled port in case the chip merely failed the probe.
        dcosPanic("console UART not found at port 0x%x", com1Port);
    }
    if (attachInterrupt(consoleLine, consoleInterrupt, nullptr) != dcos::Status::Ok) {
        dcosPanic("cannot attach the console's interrupt line %u", consoleLine);
    }

    // An application's tick rate is checked when it is compiled; an
    // impossible one still falls back to the default rather than stop the node.
    if (tickRateHz < minimumTickRateHz || tickRateHz > maximumTickRateHz) {
        tickRateHz = defaultTickRateHz;
    }
    uint32_t rate = tickRateHz;
    char value[12];
    if (boot::findCommandLineOption(bootInfo.commandLine, "tick_hz", value, sizeof value)) {
        // At most five digits, so the accumulation below cannot overflow.
        uint32_t requested = 0;
        bool numeric = value[0] != '\0';
        for (const char* p = value; *p != '\0' && numeric; ++p) {
            numeric = p - value < 5;
            numeric = numeric && *p >= '0' && *p <= '9';
            requested = requested * 10 + static_cast<uint32_t>(*p - '0');
        }
        if (numeric && requested >= Pit8254::minimumRateHz && requested <= Pit8254::maximumRateHz) {
            rate = requested;
        } else {
            runtime::format(uart, "warning: tick_hz=%s is not a rate from %lu to %lu Hz; using %lu Hz\r\n", value,
                            static_cast<unsigned long>(Pit8254::minimumRateHz),
                            static_cast<unsigned long>(Pit8254::maximumRateHz),
                            static_cast<unsigned long>(tickRateHz));
        }
    }
    const uint16_t shortenBy = crystalModel(bootInfo, Pit8254::divisorFor(rate));
    if (pit.start(rate, shortenBy) != dcos::Status::Ok) {
        dcosPanic("the 8254 refused a tick of %lu Hz", static_cast<unsigned long>(rate));
    }
    // The counts the timer really makes per tick: with a crystal model the
    // clock's reading within a tick runs over those, and the tick itself
    // still counts as the nominal period, so the clock runs fast.
    tickTimerDivisor = pit.programmedDivisor();
}

dcos::Status attachInterrupt(unsigned line, InterruptHandler handler, void* context)
{
    if (line >= interruptLineCount || line == Pic8259::cascadeLine || handler == nullptr) {
        return dcos::Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    if (attachments[line].handler != nullptr) {
        return dcos::Status::Busy;
    }
    setAttachment(line, {handler, context});
    pic.unmask(line);
    return dcos::Status::Ok;
}

dcos::Status detachInterrupt(unsigned line)
{
    if (line >= interruptLineCount) {
        return dcos::Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    pic.mask(line);
    setAttachment(line, {nullptr, nullptr});
    return dcos::Status::Ok;
}

void maskInterrupt(unsigned line)
{
    arch_x86::InterruptGuard guard;
    pic.mask(line);
}

void unmaskInterrupt(unsigned line)
{
    arch_x86::InterruptGuard guard;
    pic.unmask(line);
}

bool isInterruptMasked(unsigned line) { return pic.isMasked(line); }

bool isInterruptRequested(unsigned line)
{
    arch_x86::InterruptGuard guard;
    return line < interruptLineCount && (pic.readRequestRegister() & (1u << line)) != 0;
}

dcos::Result<dcos::DateTime> readRealTimeClock() { return rtc.read(); }

bool interruptCutShort(unsigned& line)
{
    arch_x86::InterruptGuard guard;
    const uint16_t inService = pic.readInServiceRegister();
    const uint8_t master = static_cast<uint8_t>(inService & ~(1u << Pic8259::cascadeLine));
    const uint8_t slave = static_cast<uint8_t>(inService >> 8);
    // With no handler running at most one line is in service: a slave line
    // shows on the master's cascade input as well.
    if (slave != 0) {
        line = 8 + static_cast<unsigned>(__builtin_ctz(slave));
        return true;
    }
    if (master != 0) {
        line = static_cast<unsigned>(__builtin_ctz(master));
        return true;
    }
    return false;
}

uint32_t unexpectedInterruptCount(unsigned line) { return line < interruptLineCount ? unexpected[line] : 0; }

uint32_t spuriousInterruptCount() { return spurious; }

uint32_t tickRateHz() { return pit.requestedRateHz(); }

uint64_t tickPeriodNanoseconds() { return pit.tickPeriodNanoseconds(); }

uint8_t interruptLevelOf(unsigned line) { return line < interruptLineCount ? levelOfLine[line] : 0xFF; }

void setTaskInterruptLevel(uint8_t level)
{
    uint16_t overlay = 0;
    for (unsigned line = 0; line < interruptLineCount; ++line) {
        const uint8_t lineLevel = levelOfLine[line];
        if (lineLevel != 0 && lineLevel != 0xFF && lineLevel >= level) {
            overlay = static_cast<uint16_t>(overlay | (1u << line));
        }
    }
    pic.setOverlayMask(overlay);
}

uint16_t nodeId() { return node; }

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
