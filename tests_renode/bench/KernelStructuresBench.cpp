// Benchmarks of the kernel's shared data structures (firmware/dcos/include/dcos/internal).
//
// The agents build their primitives on these, so their figures are the floor
// under Task.Create, Scheduler.Yield and the rest. Each structure gets its
// own instance here, sized statically for the largest object count, so the
// benchmarks do not disturb the running kernel.
#include "Benchmark.hpp"

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/DeadlineKey.hpp>
#include <dcos/internal/DeadlineQueue.hpp>
#include <dcos/internal/ObjectTable.hpp>
#include <dcos/internal/ReadyBitmap.hpp>
#include <dcos/internal/TimeWheel.hpp>

#include <stddef.h>
#include <stdint.h>

namespace bench {
namespace {

using dcos::ObjectId;
using dcos::Status;
using namespace dcos::internal;

// --- Kernel.ResolveId: ObjectTable::resolve, the check behind every primitive that takes an id.

struct TableObject {
    uint32_t value = 0;
};

using BenchTable = ObjectTable<TableObject, maximumObjectCount>;
constexpr uint16_t benchNode = 1;

constinit BenchTable table(dcos::ObjectType::Semaphore, benchNode);
ObjectId tableIds[maximumObjectCount];
uint32_t tableIdCount = 0;
ObjectId resolveTarget;
TableObject* volatile resolvedObject;

void clearTable()
{
    for (uint32_t i = 0; i < tableIdCount; ++i) {
        (void)table.Delete(tableIds[i]);
    }
    tableIdCount = 0;
}

Status fillTable(uint32_t objects)
{
    if (objects == 0 || objects > BenchTable::capacity()) {
        return Status::InvalidArgument;
    }
    if (table.activeCount() < objects) {
        const Status added = table.AddObjects(objects - table.activeCount());
        if (added != Status::Ok) {
            return added;
        }
    }
    while (tableIdCount < objects) {
        const dcos::Result<ObjectId> id = table.Create(ObjectId::null(), nullptr, dcos::Visibility::Local);
        if (!id.ok()) {
            return id.status();
        }
        tableIds[tableIdCount++] = id.value();
    }
    // The most recently created object: its slot is as far into the table as any.
    resolveTarget = tableIds[objects - 1];
    return table.resolve(resolveTarget).ok() ? Status::Ok : Status::Corrupted;
}

void resolveId()
{
    const dcos::Result<TableObject*> object = table.resolve(resolveTarget);
    resolvedObject = object.ok() ? object.value() : nullptr;
}

// --- Scheduler.ReadyBitmapHighest: the static scheduler's choice of the next priority.

ReadyBitmap readyBitmap;
volatile uint8_t highestReady;

// One ready task per object, spread over the priorities from the lowest up,
// so 8 tasks leave the highest ready priority at 24 and 4096 at 0.
Status fillReadyBitmap(uint32_t tasks)
{
    readyBitmap = ReadyBitmap{};
    for (uint32_t i = 0; i < tasks; ++i) {
        readyBitmap.set(static_cast<uint8_t>(ReadyBitmap::kLevels - 1 - i % ReadyBitmap::kLevels));
    }
    return Status::Ok;
}

void readyBitmapHighest()
{
    highestReady = readyBitmap.highest();
}

// --- Timer.TimeWheelInsertCancel: arming and disarming a time-out on the timer agent's wheel.

struct WheelTimer : TimeWheelNode<> {};

// A prime near 256; the timer agent chooses its own slot count.
constexpr size_t wheelSlots = 251;

TimeWheel<WheelTimer, wheelSlots> wheel;
WheelTimer pendingTimers[maximumObjectCount];
uint32_t pendingTimerCount = 0;
WheelTimer measuredTimer;
uint64_t measuredDueTick = 0;

void clearWheel()
{
    for (uint32_t i = 0; i < pendingTimerCount; ++i) {
        (void)wheel.cancel(pendingTimers[i]);
    }
    pendingTimerCount = 0;
    (void)wheel.cancel(measuredTimer);
}

// Arms one time-out per object, due on consecutive ticks after firstDue.
Status armTimers(uint32_t timers, uint64_t firstDue)
{
    if (timers == 0 || timers > maximumObjectCount) {
        return Status::InvalidArgument;
    }
    for (uint32_t i = 0; i < timers; ++i) {
        const Status armed = wheel.insert(pendingTimers[i], firstDue + i);
        if (armed != Status::Ok) {
            return armed;
        }
        pendingTimerCount = i + 1;
    }
    return Status::Ok;
}

// The common case the wheel is built for: the new time-out is due after
// every time-out already waiting in its slot (here one revolution after the
// last one armed, so its slot is never empty), and insertion stops at once.
Status armTimersForLatest(uint32_t timers)
{
    const uint64_t firstDue = wheel.currentTick() + 1;
    measuredDueTick = firstDue + timers - 1 + wheelSlots;
    return armTimers(timers, firstDue);
}

// The bad case: the new time-out is due before everything in its slot, so
// insertion walks the whole slot, about timers / wheelSlots entries.
Status armTimersForEarliest(uint32_t timers)
{
    measuredDueTick = wheel.currentTick() + 1;
    return armTimers(timers, measuredDueTick + 1);
}

void timeWheelInsertCancel()
{
    (void)wheel.insert(measuredTimer, measuredDueTick);
    (void)wheel.cancel(measuredTimer);
}

// --- Scheduler.DeadlineQueueInsertPop: a deadline task more urgent than all
// others becomes ready and is then dispatched.

struct DeadlineTask : DeadlineQueueNode {};

constexpr uint8_t deadlinePriority = 10;
constexpr uint64_t nanosecondsPerMillisecond = 1000000;

DeadlineQueue<DeadlineTask, maximumObjectCount + 1> deadlineQueue;
DeadlineTask queuedTasks[maximumObjectCount];
DeadlineTask urgentTask;
DeadlineKey urgentKey;
DeadlineTask* volatile dispatchedTask;

void clearDeadlineQueue()
{
    while (deadlineQueue.pop() != nullptr) {
    }
}

// Deadlines 1 ms apart from 10 ms on, so every key differs; the measured
// task's 1 ms deadline precedes them all.
Status fillDeadlineQueue(uint32_t tasks)
{
    if (tasks > maximumObjectCount) {
        return Status::InvalidArgument;
    }
    for (uint32_t i = 0; i < tasks; ++i) {
        const uint64_t deadlinePeriod = (10 + uint64_t{i}) * nanosecondsPerMillisecond;
        const Status queued
            = deadlineQueue.insert(queuedTasks[i], DeadlineKey::make(deadlinePriority, 0, deadlinePeriod, 0));
        if (queued != Status::Ok) {
            return queued;
        }
    }
    urgentKey = DeadlineKey::make(deadlinePriority, 0, nanosecondsPerMillisecond, 0);
    return Status::Ok;
}

void deadlineQueueInsertPop()
{
    (void)deadlineQueue.insert(urgentTask, urgentKey);
    dispatchedTask = deadlineQueue.pop();
}

} // namespace

DCOS_BENCHMARK(resolveIdBenchmark, "Kernel.ResolveId", fillTable, resolveId, Cost::Constant, .teardown = clearTable);

DCOS_BENCHMARK(readyBitmapHighestBenchmark, "Scheduler.ReadyBitmapHighest", fillReadyBitmap, readyBitmapHighest,
               Cost::Constant);

DCOS_BENCHMARK(timeWheelInsertCancelBenchmark, "Timer.TimeWheelInsertCancel", armTimersForLatest,
               timeWheelInsertCancel, Cost::Constant, .teardown = clearWheel);

DCOS_BENCHMARK(timeWheelInsertEarliestBenchmark, "Timer.TimeWheelInsertCancelEarliest", armTimersForEarliest,
               timeWheelInsertCancel, Cost::Variable, .teardown = clearWheel);

DCOS_BENCHMARK(deadlineQueueInsertPopBenchmark, "Scheduler.DeadlineQueueInsertPop", fillDeadlineQueue,
               deadlineQueueInsertPop, Cost::Logarithmic, .teardown = clearDeadlineQueue);

} // namespace bench
