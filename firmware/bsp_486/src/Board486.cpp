// Board support for the ISA i486 single-board controller (seed 9.2,
// controller node 1): an 8259A pair and an 8254 at their PC/AT addresses.
// The serial ports, the CMOS clock and the command-line options are the
// PC/AT peripherals the dual-Pentium board shares (PcPeripherals.cpp).
#include <bsp/Board.hpp>
#include <bsp/PcPeripherals.hpp>
#include <bsp/Pic8259.hpp>
#include <bsp/Pit8254.hpp>

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

Pic8259 pic(arch_x86::IoWindow::ports(masterPicPort, 2), arch_x86::IoWindow::ports(slavePicPort, 2));
Pit8254 pit(arch_x86::IoWindow::ports(pitPort, 4));

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

const BoardIdentity board{"isa486", "i486DX"};

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

static_assert(systemTickLine == 0, "BoardTick.hpp reads the tick's request as bit 0 of the master 8259");
static_assert(Pit8254::minimumRateHz == minimumTickRateHz && Pit8254::maximumRateHz == maximumTickRateHz);

void initialise(const boot::BootInfo& bootInfo, uint32_t tickRateHz)
{
    node = pc::nodeFromCommandLine(bootInfo, 1);
    pic.initialise(static_cast<uint8_t>(arch_x86::firstIrqVector));
    arch_x86::Idt::setInterruptHandler(dispatchInterrupt);
    pc::initialiseConsole();

    const uint32_t rate = pc::tickRateFromCommandLine(bootInfo, tickRateHz);
    const uint32_t shortenBy = pc::crystalShortening(bootInfo, Pit8254::divisorFor(rate));
    if (pit.start(rate, static_cast<uint16_t>(shortenBy)) != dcos::Status::Ok) {
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

uint16_t interruptLinesHeldOff()
{
    arch_x86::InterruptGuard guard;
    return pic.readMaskRegisters();
}

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

unsigned spareInterruptLine(unsigned which) { return which == 0 ? 5 : 11; }

// The ISA board has no PCI bus: nothing answers at the configuration
// ports, and an ISA card might.
bool ownsPciBus() { return false; }

dcos::Status routePciInterrupt(uint8_t, uint8_t, uint8_t, unsigned) { return dcos::Status::NotSupported; }

uint32_t unexpectedInterruptCount(unsigned line) { return line < interruptLineCount ? unexpected[line] : 0; }

uint32_t spuriousInterruptCount() { return spurious; }

uint32_t tickRateHz() { return pit.requestedRateHz(); }

uint64_t tickPeriodNanoseconds() { return pit.tickPeriodNanoseconds(); }

void setTaskInterruptLevel(uint8_t level)
{
    const uint16_t overlay = pc::linesAtOrBelowLevel(level);
    pic.setOverlayMask(overlay);
}

uint16_t nodeId() { return node; }

} // namespace bsp
