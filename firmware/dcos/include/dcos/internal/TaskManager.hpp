// The task agent's kernel side (seed 7.6): the task table, the life cycle
// of tasks, blocking and waking, events, signals and exceptions.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/Task.hpp>

#include <arch_x86/InterruptFrame.hpp>

namespace dcos::internal {

class TaskManager {
public:
    /// Software interrupts the handler trampolines use to return to the kernel.
    static constexpr uint8_t kSignalReturnVector = 0x31;
    static constexpr uint8_t kExceptionReturnVector = 0x32;

    /// Sets up the task table, the idle task and the root (super-user) task,
    /// which will run rootEntry. Called once at boot.
    static void initialise(TaskEntry rootEntry);

    /// Resolves a task id (O(1)); remote ids give Status::Remote.
    static Result<Task*> resolve(ObjectId id);

    /// Succeeds when newOwner may receive an object: the null id (the
    /// system) or a live task of this node; otherwise the id's error.
    static Status checkNewOwner(ObjectId newOwner);

    static Result<ObjectId> create(const TaskAttributes& attributes, TaskEntry entry, uintptr_t argument);
    static Status kill(Task& task);
    [[noreturn]] static void exitCurrent();
    static Status suspend(Task& task);
    static Status resume(Task& task);
    static Status changePriority(Task& task, uint8_t priority);

    /// Blocks the running task until wake() or the time-out (kWaitForever
    /// for none). Returns the status wake() gave, or Timeout. Must be called
    /// with interrupts disabled, from task context.
    static Status blockCurrent(WaitReason reason, uint64_t timeoutNs);
    /// Blocks the running task until the clock reads a time of day (SleepTill);
    /// a change of the clock moves the wake-up with it. Returns Timeout when
    /// the time came. Interrupts disabled, task context.
    static Status blockCurrentTillTimeOfDay(uint64_t timeOfDayNs);
    /// Makes a blocked task ready with the given result. O(1).
    static void wake(Task& task, Status result);

    /// Blocks the running task on an object's wait queue until wakeFirst /
    /// wakeAll or the time-out. Interrupts disabled, task context. The
    /// queue's observer is told when the waiter leaves by time-out or kill.
    static Status blockOn(WaitQueue& queue, uint64_t timeoutNs);
    /// Wakes the first waiter of a queue with result; returns it, or null. O(1).
    static Task* wakeFirst(WaitQueue& queue, Status result);
    /// Wakes every waiter of a queue with result. O(waiters).
    static void wakeAll(WaitQueue& queue, Status result);

    /// Recomputes the priority a task runs at: its static priority, raised
    /// to the most urgent waiter of every inheritance source it holds, and
    /// passes a change on along the chain of holders. O(sources held).
    static void recomputePriority(Task& task);

    static void postEvent(Task& task, uint32_t events);
    /// PostEvent's path: looks the task up and posts under one interrupt
    /// guard, with the table's inline lookup; fails as resolve() does. O(1).
    static Status postEvent(ObjectId id, uint32_t events);
    static void sendSignal(Task& task, unsigned signal);
    /// Marks an exception for delivery to task when it next runs.
    static void raiseException(Task& task, const ExceptionInfo& info);

    /// Saves and restores what a task switch must carry beyond the frame.
    static void switchContext(Task& from, Task& to);
    /// Runs before returning to task: reaps ended tasks and arranges
    /// delivery of pending exceptions and signals. Returns the frame to resume.
    /// Inline for the common case of an interrupt's exit with nothing to do.
    static arch_x86::InterruptFrame* prepareReturn(Task& task, arch_x86::InterruptFrame* frame)
    {
        if (!reapPending_ && !task.hasDeliveryPending()) {
            return frame;
        }
        return prepareReturnWithWork(task, frame);
    }

    /// CPU exceptions (vectors 0-31).
    static arch_x86::InterruptFrame* onCpuException(arch_x86::InterruptFrame* frame);
    /// Software traps (vectors 0x30-0x3F).
    static arch_x86::InterruptFrame* onTrap(arch_x86::InterruptFrame* frame);

    /// Visits every task in use, for the console's task list.
    template <typename Visitor>
    static void forEachTask(Visitor&& visit);

    /// The deepest the task's stack has been used, in bytes, found by
    /// scanning for the pattern its stack was filled with at creation.
    /// O(stack size): for the console, not for real-time paths.
    static size_t stackHighWater(const Task& task);

    static size_t taskCount();
    static Status addObjects(size_t count);
    /// A task named @p name visible from @p askingScope (Local: every task of this node).
    static Result<ObjectId> nameToObject(const char* name, Visibility askingScope = Visibility::Local);
    static const char* nameOf(ObjectId id);

    /// The task array, for forEachTask.
    static Task* taskArray();
    static size_t taskArraySize();

private:
    // Posts with interrupts already off; both postEvent paths share it.
    static void postEventLocked(Task& task, uint32_t events);

    /// prepareReturn() when a task may be reaped or something delivered.
    static arch_x86::InterruptFrame* prepareReturnWithWork(Task& task, arch_x86::InterruptFrame* frame);

public:
    /// Whether an ended task waits to be reaped (its stack freed once left).
    /// Kept by the task code beside its reap list, read by prepareReturn.
    static bool reapPending_;
};

template <typename Visitor>
void TaskManager::forEachTask(Visitor&& visit)
{
    Task* tasks = taskArray();
    for (size_t i = 0; i < taskArraySize(); ++i) {
        if (tasks[i].state != TaskState::NonExistent) {
            visit(tasks[i]);
        }
    }
}

} // namespace dcos::internal
