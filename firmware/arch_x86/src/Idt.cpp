#include <arch_x86/CpuException.hpp>
#include <arch_x86/Gdt.hpp>
#include <arch_x86/Idt.hpp>

extern "C" const uint32_t interruptStubTable[256];
extern "C" [[noreturn]] void dcosPanicWithFrame(const arch_x86::InterruptFrame* frame, const char* reason);

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

Idt::Handler exceptionHandler = unhandled;
Idt::Handler interruptHandler = unhandled;
Idt::Handler trapHandler = unhandled;
Idt::Handler outermostExitHook = unchanged;
} // namespace

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

void Idt::setInterruptHandler(Handler handler) { interruptHandler = handler; }

void Idt::setTrapHandler(Handler handler) { trapHandler = handler; }

InterruptFrame* Idt::dispatchInterrupt(InterruptFrame* frame) { return interruptHandler(frame); }

void Idt::setOutermostExitHook(Handler hook) { outermostExitHook = hook; }

} // namespace arch_x86

DCOS_ASM_REGISTER_LINKAGE arch_x86::InterruptFrame* interruptEntry(arch_x86::InterruptFrame* frame)
{
    using namespace arch_x86;
    // One read-modify-write instruction each way (interrupts are off): the
    // volatile's load, add and store would be three.
    asm volatile("incl %0" : "+m"(Idt::depth_));
    const uint32_t vector = frame->vector;
    InterruptFrame* resume;
    // Device requests first: they are the frequent ones and the ones whose
    // latency counts.
    if (vector - firstIrqVector < Idt::firstTrapVector - firstIrqVector) {
        resume = interruptHandler(frame);
    } else if (vector < exceptionVectorCount) {
        resume = exceptionHandler(frame);
    } else if (vector >= Idt::firstTrapVector && vector <= Idt::lastTrapVector) {
        resume = trapHandler(frame);
    } else {
        resume = interruptHandler(frame);
    }
    // The whole word: before the kernel enters task context the top bit is
    // set, and no task can be switched to, so the hook is not called then.
    if (Idt::depth_ == 1) {
        resume = outermostExitHook(resume);
    }
    asm volatile("decl %0" : "+m"(Idt::depth_));
    return resume;
}
