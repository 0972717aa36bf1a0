// The interrupt descriptor table and the dispatch of every vector.
//
// All 256 vectors enter through InterruptStubs.S and reach one dispatcher,
// which hands exceptions (0-31) to the installed exception handler and
// hardware interrupts to the board's interrupt controller driver. The
// handlers are plain function pointers set at start-up: no registration
// needs memory, and an unset vector is reported rather than ignored.
#pragma once

#include <arch_x86/AssemblyLinkage.hpp>
#include <arch_x86/InterruptFrame.hpp>

/// The C++ entry for every vector but the interrupt controller's lines,
/// which interrupt_common hands to the line handler itself; called from
/// interrupt_common and from the fault tasks' stubs.
DCOS_ASM_REGISTER_LINKAGE arch_x86::InterruptFrame* interruptEntry(arch_x86::InterruptFrame* frame);

namespace arch_x86 {

class Idt {
public:
    /// Handles one vector; returns the frame to resume (normally frame).
    using Handler = InterruptFrame* (*)(InterruptFrame* frame);

    /// Fills all 256 gates with interrupt gates to the entry stubs and
    /// loads the table. Until handlers are set, every vector panics.
    static void install();

    /// Replaces one gate: selector, offset and type/attribute byte as in
    /// SDM Vol. 3, 6.11 (FaultTasks.hpp turns #PF and #DF into task gates).
    static void setGate(unsigned vector, uint16_t selector, uint32_t offset, uint8_t typeAttributes);

    /// Sets the handler for the CPU exception vectors 0-31.
    static void setExceptionHandler(Handler handler);

    /// Handles one interrupt controller line (its vector less
    /// firstIrqVector). The interrupted code resumes from its own frame: a
    /// switch of tasks happens in the outermost exit hook, not here, so the
    /// line handler needs neither the frame nor to return one.
    using LineHandler = void (*)(unsigned line);

    /// Sets the handler for the interrupt controller's lines, vectors 32 up
    /// to the kernel trap range (hardware interrupts, and software ones
    /// raised on their vectors). It is given the line, never a vector
    /// outside that range, so it need not check one; a vector above the
    /// traps panics.
    static void setInterruptHandler(LineHandler handler);

    /// The vectors software traps into the kernel use (int 0x30-0x3F).
    static constexpr unsigned firstTrapVector = 0x30;
    static constexpr unsigned lastTrapVector = 0x3F;

    /// Runs the interrupt handler for @p line, as its arrival would (for an
    /// interrupt whose delivery a fault cut short).
    static void dispatchInterrupt(unsigned line);

    /// Sets the handler for the kernel trap vectors.
    static void setTrapHandler(Handler handler);

    /// Sets the function run when the outermost interrupt handler is about
    /// to return. It receives the frame to resume and returns the frame to
    /// resume instead: this is where the scheduler switches tasks, so that
    /// nested handlers never dispatch.
    static void setOutermostExitHook(Handler hook);

    /// The current nesting depth of interrupt handlers (0 in task context).
    /// Inline: every blocking service asks, on its fast path, and the
    /// masked read is one TEST of memory against an immediate.
    static unsigned nestingDepth() { return depth_ & kDepthMask; }

    /// True when no task is the caller: inside an interrupt handler, or at
    /// boot before the kernel enters task context. One word answers both,
    /// so the memory agents' fast paths, which record the calling task as
    /// a holder, pay one test for them instead of two.
    static bool outsideTaskContext()
    {
        // A CMP of the word in memory with 0, its flag the result: for
        // "!= 0" GCC loads the word and tests the register, one instruction
        // more on every memory agent's fast path.
        bool outside;
        asm("cmpl $0, %1" : "=@ccne"(outside) : "m"(depth_));
        return outside;
    }

    /// Called once, with interrupts disabled, when the first task is about
    /// to run: from then on outsideTaskContext() means an interrupt handler.
    static void enterTaskContext() { depth_ &= kDepthMask; }

private:
    friend arch_x86::InterruptFrame* (::interruptEntry)(arch_x86::InterruptFrame* frame);

    // The nesting depth in the low bits; the top bit is set from boot until
    // enterTaskContext(). The depth never reaches the top bit (each level
    // takes a stack frame), so INC and DEC never touch it.
    static constexpr unsigned kBeforeTaskContext = 0x80000000u;
    static constexpr unsigned kDepthMask = ~kBeforeTaskContext;

    // Raised and lowered around each handler, by interrupt_common for the
    // lines (InterruptStubs.S) and by interruptEntry for every other vector;
    // read by the scheduler's assembly too (TaskContextSwitch.S): hence the
    // plain symbol name. Not volatile: an interrupt always restores it
    // before the code it interrupted runs again, so that code never sees it
    // change, and interruptEntry tells the compiler through its asm
    // operands.
    static unsigned depth_ asm("dcosInterruptDepth");
};

} // namespace arch_x86
