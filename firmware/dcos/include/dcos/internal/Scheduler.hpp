// The scheduler agent's kernel side (seed 7.4).
//
// Two mechanisms, chosen per task: tasks inside a deadline scope sit in a
// binary heap ordered by (static priority, latest start time) with the
// seed's tie-breaks, and run before every other task; all other tasks sit in
// 32 FIFO ready queues under a ready bitmap, so selecting the next one is a
// single bit scan. The running task stays at the head of its queue, so a
// preempted task resumes before its equals. Each queue is a ring known by
// its head, so the round-robin step of Yield moves one pointer.
//
// Task switches happen in two places. A task that blocks, yields or readies
// a more urgent task switches at once, from task context, through
// dcosSwitchFromTask (switchFromTask, scheduler/TaskContextSwitch.S): it
// saves only its callee-saved registers and its flags.
// An interrupt handler that readies a task only marks a dispatch as pending,
// and the switch happens at the exit of the outermost interrupt
// (onOutermostExit), from the interrupted frame. Either side resumes either
// kind of saved context. A switch that must deliver a signal or an exception
// on the way, or leave a dying task, takes the dispatch trap (int 0x30) to
// the interrupt exit, where prepareReturn does that work.
#pragma once

#include <dcos/internal/DeadlineQueue.hpp>
#include <dcos/internal/IntrusiveRing.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/ReadyBitmap.hpp>
#include <dcos/internal/Task.hpp>
#include <dcos/internal/TaskManager.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/InterruptFrame.hpp>
#include <arch_x86/TaskSwitch.hpp>

/// The switch from task context (scheduler/TaskContextSwitch.S): parks the
/// caller with @p flags to restore, at *save, and resumes @p next.
extern "C" [[gnu::regparm(3)]] void dcosSwitchFromTask(uint32_t** save, dcos::internal::Task* next, uint32_t flags);

namespace dcos::internal {

class Scheduler {
public:
    /// The software interrupt a task uses to enter the dispatcher.
    static constexpr uint8_t kDispatchTrapVector = 0x30;

    /// Makes idle the task that runs when nothing else is ready.
    static void setIdleTask(Task& idle);

    /// The running task (the idle task when nothing else runs).
    static Task& current() { return *current_; }
    static bool started() { return current_ != nullptr; }

    /// Puts a task that may run into its ready queue or the deadline heap,
    /// and asks for a dispatch when it is more urgent than the running one. O(1) / O(log N).
    static void makeReady(Task& task);
    /// Takes a task out of its ready queue or the deadline heap. O(1) / O(log N).
    /// It never dispatches by itself: a caller taking the running task out
    /// finishes its bookkeeping first, then calls requestDispatch().
    static void makeUnready(Task& task);
    /// Puts back a task taken out with makeUnready after its priority or
    /// scope changed, dispatching if the running task is no longer first.
    static void requeue(Task& task);

    /// True when a is to run before b.
    static bool isMoreUrgent(const Task& a, const Task& b);
    /// The key a deadline-scheduled task is ordered by: its own scope's,
    /// or the one a waiter lends it when that is more urgent.
    /// Inline: makeReadyByDeadline then builds the key in the heap node's
    /// place instead of building it, returning it and copying it twice.
    [[gnu::always_inline]] static DeadlineKey urgencyKey(const Task& task)
    {
        if (!task.inDeadlineScope) {
            return task.inheritedDeadline;
        }
        const DeadlineKey own = DeadlineKey::make(task.priority, task.deadlineNs - task.deadlinePeriodNs,
                                                  task.deadlinePeriodNs, task.executionPeriodNs);
        return task.inheritsDeadline && task.inheritedDeadline.precedes(own) ? task.inheritedDeadline : own;
    }

    /// Asks for a task switch: at once from task context (through the
    /// dispatch trap), or at the outermost interrupt exit from a handler.
    static void requestDispatch();

    /// Holds every task switch, whether requested from task context or at
    /// an interrupt's exit, until the matching releaseDispatch(): kernel
    /// code that readies several tasks, or that ends the running task,
    /// finishes its bookkeeping before any of them runs. Nests. Interrupts
    /// may stay enabled meanwhile (the application loader creates tasks and
    /// prints under a hold); interrupt handlers still run, only the switch
    /// waits. The holder must not block.
    static void holdDispatch() { ++dispatchHolds_; }
    /// Ends a hold; a switch requested meanwhile happens now.
    static void releaseDispatch();
    /// Whether a dispatch hold is taken: the kernel is inside a critical section.
    static bool dispatchHeld() { return dispatchHolds_ != 0; }

    /// Moves the running task behind its equals (Yield, end of time slice).
    /// Returns true when another task of the same priority was waiting.
    static bool rotateCurrent();

    /// Yield from task context: rotateCurrent() and the switch to the next
    /// equal in one pass, the common case without a call to the general
    /// dispatcher. Interrupts may be enabled or not; their state is kept.
    /// Inline, so that Yield's cost is this and the switch itself.
    [[gnu::always_inline]] static void yieldCurrent()
    {
        const uint32_t flags = arch_x86::saveFlagsAndDisableInterrupts();
        Task* const task = current_;
        auto& queue = readyQueues_[task->priority];
        // The common case: a static-priority task at the head of its queue,
        // no hold. With no hold, the running task is the most urgent one, so
        // the next is the new head of its queue.
        if (!task->rotatesOnYield || dispatchHolds_ != 0 || !queue.isFront(*task)) {
            (void)rotateCurrent(); // The general rotation and dispatch.
        } else if (Task* const next = queue.rotate(); next == nullptr) {
            // Nobody of its priority waits: it runs on.
        } else if (next->hasDeliveryPending()) {
            requestDispatch(); // Rotated; the general switch delivers on the way.
        } else {
            switchDirectly(*task, *next, flags);
            return;
        }
        arch_x86::restoreFlags(flags);
    }

    /// Counts a tick against the running task's time slice.
    static void onTick();

    /// Sets the time-slice length in ticks (at least 1).
    static void setQuantumTicks(uint32_t ticks);
    static uint32_t quantumTicks() { return quantumTicks_; }

    /// Called at the exit of the outermost interrupt with the interrupted
    /// frame; returns the frame to resume.
    static arch_x86::InterruptFrame* onOutermostExit(arch_x86::InterruptFrame* frame);

    /// Starts scheduling by switching from the boot stack to the most urgent task.
    [[noreturn]] static void start();

    /// Number of task switches so far, for diagnostics and tests.
    static uint32_t switchCount() { return switchCount_; }

private:
    static Task* pickNext();
    /// makeReady for a task in a deadline scope, or lent a deadline.
    static void makeReadyByDeadline(Task& task);
    /// makeReady's dispatch when @p task, ordered by priority alone, is
    /// more urgent than @p running, ordered the same way: straight to it
    /// from task context, else requestDispatch().
    [[gnu::always_inline]] static inline void dispatchToMoreUrgent(Task& running, Task& task);

    /// The switch from task context (requestDispatch with no interrupt
    /// nesting and no hold): directly to the next task when nothing has to be
    /// delivered on the way, else through the dispatch trap.
    static void switchFromTask();
    /// An interrupt frame on a directly switched task's stack that resumes it
    /// where dcosSwitchFromTask left it, for a switch made at an interrupt's exit.
    static arch_x86::InterruptFrame* frameForDirectResume(Task& task);

    /// The direct switch itself, for its three callers (yieldCurrent,
    /// switchFromTask, dispatchToMoreUrgent): next becomes the runner, what
    /// the two tasks carry beyond registers is saved and restored, and the
    /// stacks change (dcosSwitchFromTask, TaskContextSwitch.S). Interrupts
    /// are disabled; @p flags are the caller's, restored when previous runs
    /// again. It is the caller's last act, so GCC jumps to the assembly
    /// rather than calling it, and no C++ frame stays behind on the stack.
    [[gnu::always_inline]] static void switchDirectly(Task& previous, Task& next, uint32_t flags)
    {
        current_ = &next;
        ++switchCount_;
        if (previous.switchWork || next.switchWork) {
            TaskManager::switchContext(previous, next);
        }
        dcosSwitchFromTask(&previous.resumeStack, &next, flags);
    }

    /// EFLAGS bit 1, always set (Intel SDM Vol. 1, 3.4.3).
    static constexpr uint32_t kEflagsReservedBit = 1u << 1;

    static Task* current_;
    static Task* idle_;
    static volatile bool dispatchPending_;
    static unsigned dispatchHolds_;
    static uint32_t quantumTicks_;
    static uint32_t switchCount_;
    static ReadyBitmap readyBitmap_;
    static IntrusiveRing<Task, ReadyQueueTag> readyQueues_[32];
    static DeadlineQueue<Task, kTaskCapacity> deadlineQueue_;
};

} // namespace dcos::internal
