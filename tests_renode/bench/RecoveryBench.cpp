// Resource recovery against the sizes of the other tables (issue 12: "KillTask
// / Delete recovery: proportional to what the task owns, never to table
// sizes").
//
// Task.KillTask's victim owns nothing, and only the task table grows with
// the object count. Here the victim owns one object in each of two other
// agents' tables, a binary semaphore it holds and a timer it has armed, and
// with the object count those tables are full too: with 8 objects each
// holds 8, with 4096 each holds 4096, the others owned by the shell (the
// timers armed an hour and more ahead, so the time wheel is full as well).
// The victim's recovery gives back the same two objects either way, so a
// flat figure shows that recovery walks what the task owns, not the tables.
#include "BenchSupport.hpp"

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/SemaphoreManager.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace bench {
namespace {

using dcos::AlarmNotification;
using dcos::ObjectId;
using dcos::Result;
using dcos::semaphoreAgent;
using dcos::SemaphoreAttributes;
using dcos::SemaphoreKind;
using dcos::Status;
using dcos::taskAgent;
using dcos::timerAgent;

constexpr uint64_t kMillisecond = 1000000;
constexpr uint64_t kHour = 3600ull * 1000 * kMillisecond;
constexpr AlarmNotification kNotification = AlarmNotification::event(1u << 20);

ObjectId semaphores[maximumObjectCount]; // The shell's, oldest first.
uint32_t semaphoreTotal = 0;
ObjectId timers[maximumObjectCount];
uint32_t timerTotal = 0;
ObjectId victim;
Status victimSetup = Status::Ok;

SemaphoreAttributes binary()
{
    SemaphoreAttributes attributes;
    attributes.kind = SemaphoreKind::Binary;
    attributes.initialCount = 1;
    return attributes;
}

Result<ObjectId> createSemaphore()
{
    return createGrowing([] { return semaphoreAgent.Create(binary()); }, semaphoreAgent.AddObjects);
}

Result<ObjectId> createTimer()
{
    return createGrowing([] { return timerAgent.Create(nullptr, dcos::Visibility::Local); }, timerAgent.AddObjects);
}

// The victim: creates and holds a semaphore, creates and arms a timer, then
// waits for ever. It runs above the shell, so all of it is done when
// spawnTask returns.
void ownThenBlock(uintptr_t)
{
    const Result<ObjectId> semaphore = semaphoreAgent.Create(binary());
    Status status = semaphore.status();
    if (status == Status::Ok) {
        status = semaphoreAgent.Acquire(semaphore.value(), dcos::kPoll);
    }
    if (status == Status::Ok) {
        const Result<ObjectId> timer = timerAgent.Create(nullptr, dcos::Visibility::Local);
        status = timer.ok() ? timerAgent.SetWatchDogAlarm(timer.value(), kHour, kNotification) : timer.status();
    }
    victimSetup = status;
    blockForever(0);
}

Status spawnVictim()
{
    victimSetup = Status::NotFound; // Until the victim says otherwise.
    const Result<ObjectId> id = spawnTask(ownThenBlock, kBlockedFillerPriority);
    victim = id.ok() ? id.value() : ObjectId::null();
    return id.ok() ? victimSetup : id.status();
}

// One free, active slot in each table for the victim's objects: an object
// created (growing the table if need be) and deleted at once.
Status reserveSlot(Result<ObjectId> (*create)(), Status (*remove)(ObjectId))
{
    const Result<ObjectId> id = create();
    return id.ok() ? remove(id.value()) : id.status();
}

Status populate(uint32_t count)
{
    Status status = fillTasks(count - 1, kBlockedFillerPriority);
    while (status == Status::Ok && dcos::internal::semaphoreCount() < count - 1) {
        const Result<ObjectId> id = createSemaphore();
        status = id.status();
        if (id.ok()) {
            semaphores[semaphoreTotal++] = id.value();
        }
    }
    while (status == Status::Ok && dcos::internal::TimerManager::timerCount() < count - 1) {
        const Result<ObjectId> id = createTimer();
        status = id.status();
        if (id.ok()) {
            timers[timerTotal] = id.value();
            status = timerAgent.SetWatchDogAlarm(id.value(), kHour + timerTotal * kMillisecond, kNotification);
            ++timerTotal;
        }
    }
    if (status == Status::Ok) {
        status = reserveSlot(createSemaphore, semaphoreAgent.Delete);
    }
    if (status == Status::Ok) {
        status = reserveSlot(createTimer, timerAgent.Delete);
    }
    return status == Status::Ok ? spawnVictim() : status;
}

void killVictim() { check(taskAgent.KillTask(victim)); }

void replaceVictim()
{
    forgetTask(victim);
    (void)spawnVictim();
}

void clearAll()
{
    killTasks();
    while (timerTotal > 0) {
        (void)timerAgent.Delete(timers[--timerTotal]);
    }
    while (semaphoreTotal > 0) {
        (void)semaphoreAgent.Delete(semaphores[--semaphoreTotal]);
    }
    victim = ObjectId::null();
}

// --- Task.KillTaskHolding: the victim holds one buffer and one heap
// segment, taken from the newest pool and heap, while N pools and N heaps
// exist and the shell holds one buffer or segment in each of the others.
// Its recovery gives back those two, found from the victim's lists of held
// memory; a walk over the pools and heaps (what recovery did before the
// lists) would grow with N.

constexpr size_t kBufferSize = 8;
constexpr size_t kPoolAreaBytes = dcos::BufferPoolAgent::AreaBytes(kBufferSize, 2);
constexpr size_t kHeapAreaBytes = 2 * dcos::HeapAgent::SegmentBytes(8);

alignas(8) uint8_t poolAreas[maximumObjectCount][kPoolAreaBytes];
alignas(8) uint8_t heapAreas[maximumObjectCount][kHeapAreaBytes];
ObjectId pools[maximumObjectCount];
ObjectId heaps[maximumObjectCount];
void* shellBuffers[maximumObjectCount];
void* shellSegments[maximumObjectCount];
uint32_t memoryTotal = 0; // Pools and heaps alike.
ObjectId holder;
Status holderSetup = Status::Ok;

// The victim: takes a buffer and a segment, then waits for ever. It runs
// above the shell, so it holds both when spawnTask returns.
void holdThenBlock(uintptr_t)
{
    const Result<void*> buffer = dcos::bufferPoolAgent.Allocate(pools[memoryTotal - 1]);
    const Result<void*> segment = dcos::heapAgent.Allocate(heaps[memoryTotal - 1], 8);
    holderSetup = buffer.ok() ? segment.status() : buffer.status();
    blockForever(0);
}

Status spawnHolder()
{
    holderSetup = Status::NotFound; // Until the victim says otherwise.
    const Result<ObjectId> id = spawnTask(holdThenBlock, kBlockedFillerPriority);
    holder = id.ok() ? id.value() : ObjectId::null();
    return id.ok() ? holderSetup : id.status();
}

// One more pool and heap; the shell holds a buffer and a segment of each
// except the newest, which is the victim's.
Status addPoolAndHeap(bool forVictim)
{
    const uint32_t slot = memoryTotal;
    const Result<ObjectId> pool = createGrowing(
        [slot] {
            return dcos::bufferPoolAgent.Create(poolAreas[slot], kPoolAreaBytes, kBufferSize, nullptr,
                                                dcos::Visibility::Local);
        },
        dcos::bufferPoolAgent.AddObjects);
    if (!pool.ok()) {
        return pool.status();
    }
    const Result<ObjectId> heap = createGrowing(
        [slot] { return dcos::heapAgent.Create(heapAreas[slot], kHeapAreaBytes, nullptr, dcos::Visibility::Local); },
        dcos::heapAgent.AddObjects);
    if (!heap.ok()) {
        (void)dcos::bufferPoolAgent.Delete(pool.value());
        return heap.status();
    }
    pools[slot] = pool.value();
    heaps[slot] = heap.value();
    shellBuffers[slot] = nullptr;
    shellSegments[slot] = nullptr;
    ++memoryTotal;
    if (forVictim) {
        return Status::Ok;
    }
    const Result<void*> buffer = dcos::bufferPoolAgent.Allocate(pool.value());
    shellBuffers[slot] = buffer.ok() ? buffer.value() : nullptr;
    const Result<void*> segment = dcos::heapAgent.Allocate(heap.value(), 8);
    shellSegments[slot] = segment.ok() ? segment.value() : nullptr;
    return buffer.ok() ? segment.status() : buffer.status();
}

Status populateHolding(uint32_t count)
{
    Status status = Status::Ok;
    while (status == Status::Ok && memoryTotal < count) {
        status = addPoolAndHeap(memoryTotal + 1 == count);
    }
    return status == Status::Ok ? spawnHolder() : status;
}

void killHolder() { check(taskAgent.KillTask(holder)); }

void replaceHolder()
{
    forgetTask(holder);
    (void)spawnHolder();
}

void clearHolding()
{
    killTasks(); // The victim's buffer and segment go back with it.
    while (memoryTotal > 0) {
        --memoryTotal;
        if (shellBuffers[memoryTotal] != nullptr) {
            (void)dcos::bufferPoolAgent.Return(pools[memoryTotal], shellBuffers[memoryTotal]);
        }
        if (shellSegments[memoryTotal] != nullptr) {
            (void)dcos::heapAgent.Return(heaps[memoryTotal], shellSegments[memoryTotal]);
        }
        (void)dcos::bufferPoolAgent.Delete(pools[memoryTotal]);
        (void)dcos::heapAgent.Delete(heaps[memoryTotal]);
    }
    holder = ObjectId::null();
}

} // namespace

DCOS_BENCHMARK(taskKillTaskOwningBench, "Task.KillTaskOwning", populate, killVictim, Cost::Constant,
               .restore = replaceVictim, .teardown = clearAll);
DCOS_BENCHMARK(taskKillTaskHoldingBench, "Task.KillTaskHolding", populateHolding, killHolder, Cost::Constant,
               .restore = replaceHolder, .teardown = clearHolding);

} // namespace bench
