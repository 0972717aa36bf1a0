#include <arch_x86/CpuException.hpp>
#include <arch_x86/Gdt.hpp>
#include <arch_x86/Idt.hpp>

extern "C" const uint32_t interruptStubTable[256];
extern "C" [[noreturn]] void dcosPanicWithFrame(const arch_x86::InterruptFrame* frame, const char* reason);
extern "C" [[noreturn]] void dcosPanic(const char* format, ...) __attribute__((format(printf, 1, 2)));

namespace arch_x86 {

namespace {

// A 32-bit interrupt gate (Intel SDM Vol. 3, 6.11): present, DPL 0, type 0xE.
// An interrupt gate clears IF on entry, so a handler starts with interrupts
// off and decides itself whether to allow nesting.
constexpr uint8_t gatePresentRing0Interrupt32 = 0x8E;

struct [[gnu::packed]] Gate {
    uint16_t offsetLow;
    uint16_t selector;
    uint8_t zero;
    uint8_t typeAttributes;
    uint16_t offsetHigh;
};
static_assert(sizeof(Gate) == 8);

struct [[gnu::packed]] TablePointer {
    uint16_t limit;
    uint32_t base;
};

alignas(8) Gate gates[256];

InterruptFrame* unhandled(InterruptFrame* frame)
{
    dcosPanicWithFrame(frame, "no handler for this vector");
}

InterruptFrame* unchanged(InterruptFrame* frame) { return frame; }

// Until the board sets its handler, a line's interrupt is as unexpected as
// any vector without one; the frame is not at hand, so the report names the line.
void unhandledLine(unsigned line) { dcosPanic("interrupt on line %u before the board set its handler", line); }

Idt::Handler exceptionHandler = unhandled;
Idt::Handler trapHandler = unhandled;
} // namespace

// Read by interrupt_common (InterruptStubs.S), which dispatches the lines
// itself: hence plain names and external linkage.
extern "C" {
constinit Idt::LineHandler dcosInterruptLineHandler = unhandledLine;
constinit Idt::Handler dcosOutermostExitHook = unchanged;
}

unsigned Idt::depth_ = Idt::kBeforeTaskContext;

void Idt::install()
{
    for (unsigned vector = 0; vector < 256; ++vector) {
        const uint32_t offset = interruptStubTable[vector];
        gates[vector] = Gate{static_cast<uint16_t>(offset & 0xFFFF), Gdt::kernelCode, 0,
                             gatePresentRing0Interrupt32, static_cast<uint16_t>(offset >> 16)};
    }
    const TablePointer pointer{sizeof gates - 1, static_cast<uint32_t>(reinterpret_cast<uintptr_t>(gates))};
    asm volatile("lidt %0" : : "m"(pointer) : "memory");
}

void Idt::setGate(unsigned vector, uint16_t selector, uint32_t offset, uint8_t typeAttributes)
{
    gates[vector & 0xFF] = Gate{static_cast<uint16_t>(offset & 0xFFFF), selector, 0, typeAttributes,
                                static_cast<uint16_t>(offset >> 16)};
}

void Idt::setExceptionHandler(Handler handler) { exceptionHandler = handler; }

void Idt::setInterruptHandler(LineHandler handler) { dcosInterruptLineHandler = handler; }

void Idt::setTrapHandler(Handler handler) { trapHandler = handler; }

void Idt::dispatchInterrupt(unsigned line) { dcosInterruptLineHandler(line); }

void Idt::setOutermostExitHook(Handler hook) { dcosOutermostExitHook = hook; }

} // namespace arch_x86

DCOS_ASM_REGISTER_LINKAGE arch_x86::InterruptFrame* interruptEntry(arch_x86::InterruptFrame* frame)
{
    using namespace arch_x86;
    // One read-modify-write instruction each way (interrupts are off): a
    // load, add and store would be three.
    asm volatile("incl %0" : "+m"(Idt::depth_));
    const uint32_t vector = frame->vector;
    InterruptFrame* resume;
    // The interrupt controller's lines never come here: interrupt_common
    // hands them to the line handler itself, for their latency's sake.
    if (vector < exceptionVectorCount) {
        resume = exceptionHandler(frame);
    } else if (vector >= Idt::firstTrapVector && vector <= Idt::lastTrapVector) {
        resume = trapHandler(frame);
    } else {
        // Above the traps: no interrupt controller line raises these.
        resume = unhandled(frame);
    }
    // The whole word: before the kernel enters task context the top bit is
    // set, and no task can be switched to, so the hook is not called then.
    // interrupt_common makes the same test for the lines.
    if (Idt::depth_ == 1) {
        resume = dcosOutermostExitHook(resume);
    }
    asm volatile("decl %0" : "+m"(Idt::depth_));
    return resume;
}

// The constants interrupt_common spells as numbers.
static_assert(arch_x86::firstIrqVector == 32 && arch_x86::Idt::firstTrapVector == 48,
              "InterruptStubs.S: the lines are vectors 32 to 47");
