// Benchmarks of the kernel's switching paths (seed Table 9.11): context
// switch, floating-point context, interrupt latency, and the static and
// deadline scheduling decisions.
//
// All are self-timed (bench::Options::selfTimed): the interval starts with
// bench::markStart() in one task and ends with bench::markEnd() in the task
// or interrupt handler that runs next, so what each figure includes is
// exactly the code between those two reads of the time-stamp counter;
// docs/performance.md describes it for each. The object count is the number
// of tasks in the system, partners included.
#include "BenchSupport.hpp"

#include <dcos/SchedulerAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>

#include <arch_x86/InterruptFrame.hpp>

namespace bench {
namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::schedulerAgent;
using dcos::Status;
using dcos::taskAgent;

constexpr uint64_t kMillisecond = 1000000;
constexpr uint64_t kHour = 3600ull * 1000 * kMillisecond;

void clearAll() { killTasks(); }

// --- Kernel.ContextSwitch and Kernel.FloatingPointContext: two partner
// tasks at the shell's priority take turns by Yield. The shell's measure()
// yields to the first, which marks the start and yields to the second,
// which marks the end as soon as its own Yield returns, then yields back to
// the shell. The interval is task A's Yield call, the dispatch trap, the
// switch and task B's return from its Yield call.

void markStartThenYield(uintptr_t)
{
    for (;;) {
        markStart();
        (void)schedulerAgent.Yield();
    }
}

void yieldThenMarkEnd(uintptr_t)
{
    for (;;) {
        (void)schedulerAgent.Yield();
        markEnd();
    }
}

Status spawnYieldingPair(uint32_t tasks, bool floatingPoint)
{
    const uint8_t priority = selfPriority();
    Result<ObjectId> id = spawnTask(markStartThenYield, priority, 0, nullptr, floatingPoint);
    if (id.ok()) {
        id = spawnTask(yieldThenMarkEnd, priority, 0, nullptr, floatingPoint);
    }
    if (!id.ok()) {
        return id.status();
    }
    return fillTasks(tasks, kBlockedFillerPriority);
}

Status populateForSwitch(uint32_t tasks) { return spawnYieldingPair(tasks, false); }
Status populateForFloatingPointSwitch(uint32_t tasks) { return spawnYieldingPair(tasks, true); }

void yieldToPartners() { (void)schedulerAgent.Yield(); }

// --- Kernel.InterruptLatency: a routine installed with InstallISR on the
// spare line 5 whose first action reads the time-stamp counter; a software
// "int $0x25" (vector 0x20 + 5) right after the start mark stands in for the
// device's request.

constexpr unsigned kSpareLine = 5;

void markEndInRoutine(void*) { markEnd(); }

Status populateWithRoutine(uint32_t tasks)
{
    const Status status = dcos::systemAgent.InstallISR(kSpareLine, markEndInRoutine, nullptr);
    return status != Status::Ok ? status : fillTasks(tasks, kBlockedFillerPriority);
}

void raiseSpareLine()
{
    static_assert(arch_x86::firstIrqVector + kSpareLine == 0x25);
    markStart();
    asm volatile("int $0x25" ::: "memory");
}

void removeRoutineAndClear()
{
    (void)dcos::systemAgent.RemoveISR(kSpareLine);
    clearAll();
}

// --- Kernel.StaticScheduling: the shell posts the event a blocked task of
// higher priority waits for; the interval runs from the PostEvent call to
// that task's first instruction after its ReceiveEvent returns: the wake-up,
// the static scheduler's choice (ready bitmap, queue head) and the switch.
// The other tasks are ready fillers below the shell's priority, so the
// ready queues are populated.

constexpr uint32_t kWakeEvent = 1u << 3;
constexpr uint8_t kUrgentPriority = 10;
ObjectId urgentTask;

void waitThenMarkEnd(uintptr_t)
{
    for (;;) {
        (void)taskAgent.ReceiveEvent(kWakeEvent, dcos::EventWait::Any, dcos::kWaitForever);
        markEnd();
    }
}

Status populateForStaticScheduling(uint32_t tasks)
{
    const Result<ObjectId> id = spawnTask(waitThenMarkEnd, kUrgentPriority);
    if (!id.ok()) {
        return id.status();
    }
    urgentTask = id.value();
    return fillTasks(tasks, kReadyFillerPriority);
}

void wakeUrgentTask()
{
    markStart();
    (void)taskAgent.PostEvent(urgentTask, kWakeEvent);
}

// --- Kernel.DynamicScheduling: as StaticScheduling, but every task is in a
// deadline scope, so readying goes through the deadline heap (O(log n)).
// The shell enters a scope of its own first; the fillers enter theirs when
// the shell wakes them ("set at next block") and, being of lower static
// priority than the shell, stay ready in the heap behind it. The woken task
// is of higher static priority than everyone, so it goes to the heap's root.

constexpr uint32_t kEnterScopeEvent = 1u << 4;

void enterScopeThenMarkEnd(uintptr_t)
{
    (void)schedulerAgent.SetDeadline(dcos::DeadlineStart::AtNextBlock, kMillisecond, kHour);
    waitThenMarkEnd(0);
}

// Its deadline period differs per filler, so the heap holds distinct keys.
void enterScopeThenBlock(uintptr_t index)
{
    (void)schedulerAgent.SetDeadline(dcos::DeadlineStart::AtNextBlock, kMillisecond, kHour + index * kMillisecond);
    (void)taskAgent.ReceiveEvent(kEnterScopeEvent, dcos::EventWait::Any, dcos::kWaitForever);
    blockForever(0);
}

ObjectId deadlineFillers[maximumObjectCount];
uint32_t deadlineFillerCount = 0;

// The woken task U and deadline fillers until there are @p tasks tasks, or
// exactly @p deadlineTasks fillers when that is not zero (the other tasks
// then block outside any scope); then the shell enters its scope and wakes
// the fillers into theirs.
Status populateDeadlineTasks(uint32_t tasks, uint32_t deadlineTasks)
{
    deadlineFillerCount = 0;
    const Result<ObjectId> id = spawnTask(enterScopeThenMarkEnd, kUrgentPriority);
    if (!id.ok()) {
        return id.status();
    }
    urgentTask = id.value();
    // Each filler runs at once (priority 20), arms its scope and blocks; it
    // is then moved below the shell.
    while (deadlineTasks != 0 ? deadlineFillerCount < deadlineTasks : taskCount() < tasks) {
        const Result<ObjectId> filler = spawnTask(enterScopeThenBlock, kBlockedFillerPriority, deadlineFillerCount);
        if (!filler.ok()) {
            return filler.status();
        }
        deadlineFillers[deadlineFillerCount++] = filler.value();
        (void)taskAgent.ChangePriority(filler.value(), kReadyFillerPriority);
    }
    if (const Status filled = fillTasks(tasks, kBlockedFillerPriority); filled != Status::Ok) {
        return filled;
    }
    const Status scope = schedulerAgent.SetDeadline(dcos::DeadlineStart::Now, kMillisecond, kHour);
    if (scope != Status::Ok) {
        return scope;
    }
    for (uint32_t i = 0; i < deadlineFillerCount; ++i) {
        (void)taskAgent.PostEvent(deadlineFillers[i], kEnterScopeEvent);
    }
    return Status::Ok;
}

Status populateForDynamicScheduling(uint32_t tasks) { return populateDeadlineTasks(tasks, 0); }

// --- Kernel.DynamicScheduling64: as DynamicScheduling, with 64 ready
// deadline tasks whatever the object count (issue 12's budget is for 64):
// the heap the woken task enters is the same with 8 objects (then 66 tasks,
// the least this bench can have) and with 4,096 (the others blocked outside
// any scope), so the figure is flat.

constexpr uint32_t kReadyDeadlineTasks = 64;

Status populateFor64DeadlineTasks(uint32_t tasks) { return populateDeadlineTasks(tasks, kReadyDeadlineTasks); }

// The tasks go first: once the shell left its scope, the fillers in theirs
// would all run before it.
void leaveScopeAndClear()
{
    clearAll();
    deadlineFillerCount = 0;
    (void)schedulerAgent.ClearDeadline();
}

} // namespace

DCOS_BENCHMARK(contextSwitchBench, "Kernel.ContextSwitch", populateForSwitch, yieldToPartners, Cost::Constant,
               .teardown = clearAll, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(floatingPointContextBench, "Kernel.FloatingPointContext", populateForFloatingPointSwitch,
               yieldToPartners, Cost::Constant, .teardown = clearAll, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(interruptLatencyBench, "Kernel.InterruptLatency", populateWithRoutine, raiseSpareLine, Cost::Constant,
               .teardown = removeRoutineAndClear, .selfTimed = true);
DCOS_BENCHMARK(staticSchedulingBench, "Kernel.StaticScheduling", populateForStaticScheduling, wakeUrgentTask,
               Cost::Constant, .teardown = clearAll, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(dynamicSchedulingBench, "Kernel.DynamicScheduling", populateForDynamicScheduling, wakeUrgentTask,
               Cost::Logarithmic, .teardown = leaveScopeAndClear, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(dynamicScheduling64Bench, "Kernel.DynamicScheduling64", populateFor64DeadlineTasks, wakeUrgentTask,
               Cost::Constant, .teardown = leaveScopeAndClear, .interruptsEnabled = true, .selfTimed = true);

} // namespace bench
