// Page faults and double faults handled on stacks of their own.
//
// A stack overflow leaves the faulting task without a stack to push an
// exception frame on: with an ordinary interrupt gate the processor would
// turn the page fault into a double fault and then a triple fault, which
// resets the board without a word. So vectors 8 (#DF) and 14 (#PF) enter
// task gates (Intel SDM Vol. 3, 7.3 and 6.11): the processor saves the
// faulting context in the main TSS and switches to a fault task with its
// own stack and TSS.
//
// The page-fault task does as little as possible. It copies the saved
// context into an InterruptFrame on a recovery stack, records the fault,
// and points the main TSS at a recovery entry that runs that frame through
// the ordinary exception path (interruptEntry), as if the fault had been
// taken there. The kernel then reports it and ends the faulting task, and
// the outermost interrupt exit switches to another task: the dead task's
// stack is never touched again. A fault the kernel cannot blame on a task,
// and every double fault, ends in a panic report printed from the fault
// task's own stack.
#pragma once

#include <arch_x86/InterruptFrame.hpp>

#include <stdint.h>

namespace arch_x86 {

/// What the page-fault task saw, for the kernel's report.
struct FaultRecord {
    uint32_t vector = 0;
    uint32_t errorCode = 0;
    /// CR2: the linear address whose access faulted.
    uint32_t address = 0;
    /// The faulting context's stack pointer (the frame itself lives elsewhere).
    uint32_t stackPointer = 0;
};

/// Page fault error code bits (SDM Vol. 3, 4.7, Figure 4-12).
constexpr uint32_t pageFaultPresent = 1u << 0;
constexpr uint32_t pageFaultWrite = 1u << 1;

class FaultTasks {
public:
    /// Loads the main TSS into the task register and routes #PF and #DF to
    /// their fault tasks. Needs paging on (the fault tasks load CR3) and
    /// the IDT installed.
    static void install();

    /// Whether frame is the one the page-fault task built for a fault, and
    /// if so what it recorded. The record stays valid until the next fault.
    static bool isFaultFrame(const InterruptFrame* frame);
    static const FaultRecord& lastFault();

    /// The size of each fault task's stack and of the recovery stack.
    static constexpr uint32_t kStackBytes = 8192;
};

} // namespace arch_x86
