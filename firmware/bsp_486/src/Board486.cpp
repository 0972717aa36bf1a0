// Board support for the ISA i486 single-board controller (seed 9.2,
// controller node 1): an 8259A pair, an 8254 and a 16550 on COM1, at their
// PC/AT addresses.
#include <bsp/Board.hpp>
#include <bsp/Pic8259.hpp>
#include <bsp/Pit8254.hpp>
#include <bsp/Uart16550.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/Idt.hpp>
#include <boot/Panic.hpp>

namespace bsp {

namespace {

// PC/AT port assignments.
constexpr uint16_t masterPicPort = 0x20;
constexpr uint16_t slavePicPort = 0xA0;
constexpr uint16_t pitPort = 0x40;
constexpr uint16_t com1Port = 0x3F8;

Pic8259 pic(arch_x86::IoWindow::ports(masterPicPort, 2), arch_x86::IoWindow::ports(slavePicPort, 2));
Pit8254 pit(arch_x86::IoWindow::ports(pitPort, 4));
Uart16550 uart(arch_x86::IoWindow::ports(com1Port, 8));

struct Attachment {
    InterruptHandler handler;
    void* context;
};

Attachment attachments[interruptLineCount];
uint32_t unexpected[interruptLineCount];
uint32_t spurious;

const BoardIdentity board{"isa486", "i486DX"};

// Writes straight to the UART, for the panic path.
class PolledConsole final : public runtime::CharacterSink {
public:
    void put(char character) override { uart.putPolled(character); }
};

PolledConsole polledConsole;

void consoleInterrupt(void*) { uart.handleInterrupt(); }

arch_x86::InterruptFrame* dispatchInterrupt(arch_x86::InterruptFrame* frame)
{
    const unsigned line = frame->vector - arch_x86::firstIrqVector;
    if (line >= interruptLineCount) {
        dcosPanicWithFrame(frame, "interrupt on a vector no device uses");
    }
    if (!pic.isGenuine(line)) {
        // A spurious IRQ 15 still occupied the master's cascade input.
        if (line == 15) {
            pic.endOfInterrupt(Pic8259::cascadeLine);
        }
        ++spurious;
        return frame;
    }
    const Attachment& attachment = attachments[line];
    if (attachment.handler != nullptr) {
        attachment.handler(attachment.context);
    } else {
        // Nobody owns this line: mask it so it cannot storm, and count it.
        ++unexpected[line];
        pic.mask(line);
    }
    pic.endOfInterrupt(line);
    return frame;
}

} // namespace

const BoardIdentity& identity() { return board; }

void initialise(const boot::BootInfo& bootInfo)
{
    pic.initialise(static_cast<uint8_t>(arch_x86::firstIrqVector));
    arch_x86::Idt::setInterruptHandler(dispatchInterrupt);

    if (uart.initialise(consoleBaud) != dcos::Status::Ok) {
        // No console means no way to report anything; the panic path still
        // tries the polled port in case the chip merely failed the probe.
        dcosPanic("console UART not found at port 0x%x", com1Port);
    }
    attachInterrupt(consoleLine, consoleInterrupt, nullptr);

    uint32_t rate = defaultTickRateHz;
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
                            static_cast<unsigned long>(defaultTickRateHz));
        }
    }
    pit.start(rate);
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
    attachments[line] = {handler, context};
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
    attachments[line] = {nullptr, nullptr};
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

uint32_t unexpectedInterruptCount(unsigned line) { return line < interruptLineCount ? unexpected[line] : 0; }

uint32_t spuriousInterruptCount() { return spurious; }

uint32_t tickRateHz() { return pit.requestedRateHz(); }

uint64_t tickPeriodNanoseconds() { return pit.tickPeriodNanoseconds(); }

runtime::CharacterSink& console() { return uart; }

bool consoleRead(char& character) { return uart.read(character); }

bool consoleHasInput() { return uart.hasInput(); }

} // namespace bsp

namespace boot {

runtime::CharacterSink& panicConsole() { return bsp::polledConsole; }

} // namespace boot
