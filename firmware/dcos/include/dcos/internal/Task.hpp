// The task object: everything the kernel keeps about one task (seed 7.6).
//
// Task objects live in a static array beside the task table; an id resolves
// to one in O(1). All lists a task joins are intrusive (ready queue, wait
// list, time wheel, deadline heap), so blocking and readying never allocate.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/DeadlineKey.hpp>
#include <dcos/internal/DeadlineQueue.hpp>
#include <dcos/internal/HeldList.hpp>
#include <dcos/internal/IntrusiveList.hpp>
#include <dcos/internal/TimeoutEntry.hpp>
#include <dcos/internal/WaitQueue.hpp>

#include <arch_x86/InterruptFrame.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

struct ReadyQueueTag;

/// Why a blocked task waits.
enum class WaitReason : uint8_t {
    None,
    Sleep,
    Events,
    Object, ///< A wait list of another agent (semaphore, port, ...).
};

/// The i387 state FSAVE stores in 32-bit protected mode (108 bytes).
struct FpuState {
    uint8_t bytes[108];
};

/// A source of inherited priority: an object whose waiters lend their
/// priority to the task holding it (a binary semaphore with priority
/// inheritance, seed 7.11). The holder keeps its sources in a list, so it
/// runs at the most urgent priority among all their waiters.
struct InheritanceSourceTag;
struct InheritanceSource : IntrusiveListNode<InheritanceSourceTag> {
    explicit InheritanceSource(WaitQueue::Order order) : waiters(order) {}
    WaitQueue waiters;
    Task* holder = nullptr;
    /// Whether the waiters lend their priority to the holder. A source that
    /// does not is still listed with its holder, so that the objects a task
    /// holds are found without searching every table when it dies.
    bool lendsPriority = false;
};

struct Task : IntrusiveListNode<ReadyQueueTag>, DeadlineQueueNode, WaitListNode<WaitQueueTag> {
    Task() : wakeTimeout(TimeoutEntry::Kind::TaskWake, this), deadlineTimeout(TimeoutEntry::Kind::DeadlineMiss, this) {}

    ObjectId id;
    /// Ready also for the running task: Executing is reported for the
    /// scheduler's current task, not stored, so no transition is missed.
    TaskState state = TaskState::NonExistent;
    bool suspended = false;     ///< Suspend() holds the task even when it could run.
    uint8_t basePriority = 0;   ///< The static priority set by Create and ChangePriority.
    uint8_t priority = 0;       ///< The priority it runs at (inheritance may raise it).
    bool timeSlicing = false;
    bool floatingPoint = false;
    bool superUser = false;
    bool idle = false;          ///< The idle task: never queued, runs when nothing else can.
    bool kernelTask = false;    ///< idle or the root (console): only a super user may kill or suspend it.
    ObjectId process;           ///< The process the task belongs to.

    // Execution context: where a task that is not running resumes. A task
    // switched away at an interrupt's exit left a whole interrupt frame
    // (savedFrame); one that left from task context through the direct
    // switch left only its callee-saved registers, at resumeStack (not null
    // exactly while it is parked that way).
    arch_x86::InterruptFrame* savedFrame = nullptr;
    uint32_t* resumeStack = nullptr;
    uint8_t* stackBase = nullptr; ///< Lowest byte; the guard page lies below it.
    size_t stackSize = 0;         ///< Usable bytes: the size asked for, rounded to whole pages.
    TaskEntry entry = nullptr;
    uintptr_t argument = 0;
    FpuState fpu{};

    // Time slicing.
    uint32_t sliceTicksLeft = 0;

    // Blocking.
    WaitReason waitReason = WaitReason::None;
    Status wakeStatus = Status::Ok;
    TimeoutEntry wakeTimeout;
    WaitQueue* waitingOn = nullptr; ///< The queue of the object it waits for, if any.
    uintptr_t waitData = 0;         ///< What the waiter asked for or received (agent-defined).
    /// SleepTill: the wake time-out is a time of day, which moves with the clock.
    bool sleepsTillTimeOfDay = false;
    uint64_t wakeTimeOfDayNs = 0;

    // The objects this task holds (binary semaphores); those that lend
    // priority set the priority it runs at.
    IntrusiveList<InheritanceSource, InheritanceSourceTag> heldSources;

    // Event flags.
    uint32_t events = 0;
    uint32_t awaitedEvents = 0;
    EventWait awaitedMode = EventWait::Any;
    uint32_t receivedEvents = 0;

    // Signals.
    uint32_t pendingSignals = 0;
    uint32_t signalMask = 0;
    SignalHandler signalHandler = nullptr;
    // While a signal handler runs, the interrupted frame's registers wait
    // here; the frame's stack slot is where the handler's trap comes back.
    bool inSignalHandler = false;
    arch_x86::InterruptFrame signalSavedFrame{};
    uintptr_t signalFrameAddress = 0;
    Status signalSavedWakeStatus = Status::Ok;

    // Exceptions.
    ExceptionHandler exceptionHandler = nullptr;
    bool exceptionPending = false;
    ExceptionInfo pendingException{};
    bool inExceptionHandler = false;
    arch_x86::InterruptFrame exceptionSavedFrame{};
    uintptr_t exceptionFrameAddress = 0;
    ExceptionInfo activeException{};
    Status exceptionSavedWakeStatus = Status::Ok;

    // Deadline scope (seed 7.4.1).
    bool inDeadlineScope = false;
    /// A deadline lent by a waiter in a deadline scope, through a semaphore
    /// with priority inheritance this task holds (seed 7.11): the task is
    /// scheduled with that urgency, though its own scope (and its timing
    /// exceptions) stay as they are.
    bool inheritsDeadline = false;
    DeadlineKey inheritedDeadline{};
    /// Set while queued on a WaitQueue as a deadline-scheduled waiter.
    bool queuedWithDeadline = false;
    bool deadlineAtNextBlock = false;
    uint64_t executionPeriodNs = 0;
    uint64_t deadlinePeriodNs = 0;
    uint64_t deadlineNs = 0;
    TimeoutEntry deadlineTimeout;

    // Interrupt level (seed 7.3.3); kNoInterruptLevel masks nothing.
    uint8_t interruptLevel = 0xFF;

    // Profiling (seed 7.4.2).
    bool profiling = false;
    uint64_t runStartedNs = 0;
    uint64_t profileAccumulatedNs = 0;
    uint32_t profileSamples = 0;
    uint64_t profileMinimumNs = 0;
    uint64_t profileMaximumNs = 0;
    uint64_t profileTotalNs = 0;

    /// Whether switching to or from this task has more to do than swap its
    /// registers (TaskManager::switchContext): its FPU state, profiling, or
    /// an interrupt level. refreshSwitchWork() keeps it wherever those change,
    /// so that the common switch tests one byte per task.
    bool switchWork = false;

    /// Whether the scheduler orders this task by a deadline: its own scope,
    /// or one a waiter lends it.
    bool schedulesByDeadline() const { return inDeadlineScope || inheritsDeadline; }

    /// Whether Yield may simply rotate this task's ready queue: it is not
    /// the idle task and no deadline orders it. One byte, so that Yield's
    /// fast path tests one flag rather than three; setDeadlineScope,
    /// setInheritsDeadline and the scheduler's setIdleTask keep it.
    bool rotatesOnYield = true;

    void setDeadlineScope(bool inScope)
    {
        inDeadlineScope = inScope;
        refreshRotatesOnYield();
    }
    void setInheritsDeadline(bool inherits)
    {
        inheritsDeadline = inherits;
        refreshRotatesOnYield();
    }
    void refreshRotatesOnYield() { rotatesOnYield = !idle && !schedulesByDeadline(); }

    void refreshSwitchWork() { switchWork = floatingPoint || profiling || interruptLevel != 0xFF; }

    /// Whether something waits to be delivered before the task runs on: an
    /// exception or an unmasked signal (TaskManager::prepareReturn, which
    /// works on an interrupt frame). A pending signal whose handler is busy
    /// or absent also counts; the full path then finds nothing to do, which
    /// costs time, never correctness. Kept in one byte by the setters below,
    /// the only writers of the three fields it summarises, because every
    /// switch and every interrupt's exit asks.
    bool hasDeliveryPending() const { return deliveryPending; }

    void postSignal(unsigned signal)
    {
        pendingSignals |= 1u << signal;
        refreshDeliveryPending();
    }
    void clearSignal(unsigned signal)
    {
        pendingSignals &= ~(1u << signal);
        refreshDeliveryPending();
    }
    void setSignalMask(uint32_t mask)
    {
        signalMask = mask;
        refreshDeliveryPending();
    }
    void setExceptionPending(bool pending)
    {
        exceptionPending = pending;
        refreshDeliveryPending();
    }

private:
    friend struct TaskAssemblyLayout; // Checks the offsets scheduler/TaskContextSwitch.S uses.

    bool deliveryPending = false;

    void refreshDeliveryPending() { deliveryPending = exceptionPending || (pendingSignals & ~signalMask) != 0; }

public:
    // The memory this task holds (HeldList.hpp): its buffers and its heap
    // segments, so that recovery walks only these. Last, so that the offsets
    // the assembly uses stay where they are.
    HeldHead heldBuffers{kHeldEnd, kHeldEnd};
    HeldHead heldSegments{kHeldEnd, kHeldEnd};
};

} // namespace dcos::internal
