// Benchmarks of the AddObjects configuration service of every agent (seed
// Tables 9.2 and 9.4 to 9.10; "Variable": O(count)), and of the distributed
// shared memory agent's AddSubscribers.
//
// AddObjects activates eight more slots of a table per call, and a table
// never gives slots back, so these benchmarks need tables that earlier
// benchmarks have not fully activated: mk/bench.mk links this file before
// every benchmark that fills a table. With 4096 objects a table is full by
// definition (4096 is the capacity, the 12-bit index limit), so the
// 4096-object figure is refused with "object table full".
#include "BenchSupport.hpp"

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/Device.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace bench {
namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

// Every call, warm-up and measured, activates eight slots; this leaves room
// for the default repeat count.
constexpr uint32_t kSlotsNeeded = 8 * 64;


Status roomFor(uint32_t objects)
{
    return objects + kSlotsNeeded <= maximumObjectCount ? Status::Ok : Status::TableFull;
}

// --- Task.AddObjects with that many tasks.

Status tasksWithRoom(uint32_t tasks)
{
    const Status room = roomFor(tasks);
    return room != Status::Ok ? room : fillTasks(tasks, kBlockedFillerPriority);
}

void addTaskSlots() { check(dcos::taskAgent.AddObjects(8)); }

// --- Timer.AddObjects with that many timers.

ObjectId timers[maximumObjectCount];
uint32_t timerCount = 0;

Status timersWithRoom(uint32_t count)
{
    const Status room = roomFor(count);
    if (room != Status::Ok) {
        return room;
    }
    while (timerCount < count) {
        Result<ObjectId> id = dcos::timerAgent.Create(nullptr, dcos::Visibility::Local);
        if (id.status() == Status::TableFull && dcos::timerAgent.AddObjects(8) == Status::Ok) {
            id = dcos::timerAgent.Create(nullptr, dcos::Visibility::Local);
        }
        if (!id.ok()) {
            return id.status();
        }
        timers[timerCount++] = id.value();
    }
    return Status::Ok;
}

void deleteTimers()
{
    while (timerCount > 0) {
        (void)dcos::timerAgent.Delete(timers[--timerCount]);
    }
}

void addTimerSlots() { check(dcos::timerAgent.AddObjects(8)); }

// --- System.AddObjects with that many devices.

class NullDevice final : public dcos::Device {
    Status Probe() override { return Status::Ok; }
};

NullDevice drivers[maximumObjectCount];
ObjectId devices[maximumObjectCount];
uint32_t deviceCount = 0;

Status devicesWithRoom(uint32_t count)
{
    const Status room = roomFor(count);
    if (room != Status::Ok) {
        return room;
    }
    while (deviceCount < count) {
        NullDevice& driver = drivers[deviceCount];
        Result<ObjectId> id = dcos::systemAgent.Create(driver, nullptr, dcos::Visibility::Local);
        if (id.status() == Status::TableFull && dcos::systemAgent.AddObjects(8) == Status::Ok) {
            id = dcos::systemAgent.Create(driver, nullptr, dcos::Visibility::Local);
        }
        if (!id.ok()) {
            return id.status();
        }
        devices[deviceCount++] = id.value();
    }
    return Status::Ok;
}

void deleteDevices()
{
    while (deviceCount > 0) {
        (void)dcos::systemAgent.Delete(devices[--deviceCount]);
    }
}

void addDeviceSlots() { check(dcos::systemAgent.AddObjects(8)); }

// --- AddObjects of the memory, communication and synchronisation agents,
// and Dsm.AddSubscribers. As above, the 4096-object figure is refused
// before anything is created, so only eight objects of each need storage.

constexpr uint32_t kSmallPopulation = 8;

// Creates objects with create(i) until count exist, growing the table with
// addObjects(8) when it is full; remembers their ids in ids.
template <typename Create, typename AddObjects>
Status createWithRoom(uint32_t count, ObjectId* ids, uint32_t& created, Create create, AddObjects addObjects)
{
    const Status room = count <= kSmallPopulation ? roomFor(count) : Status::TableFull;
    if (room != Status::Ok) {
        return room;
    }
    while (created < count) {
        Result<ObjectId> id = create(created);
        if (id.status() == Status::TableFull && addObjects(8) == Status::Ok) {
            id = create(created);
        }
        if (!id.ok()) {
            return id.status();
        }
        ids[created++] = id.value();
    }
    return Status::Ok;
}

// Buffer pools of two 8-byte buffers.
constexpr size_t kPoolAreaBytes = dcos::BufferPoolAgent::AreaBytes(8, 2);
alignas(8) uint8_t poolAreas[kSmallPopulation][kPoolAreaBytes];
ObjectId pools[kSmallPopulation];
uint32_t poolCount = 0;

Status poolsWithRoom(uint32_t count)
{
    return createWithRoom(
        count, pools, poolCount,
        [](uint32_t i) {
            return dcos::bufferPoolAgent.Create(poolAreas[i], kPoolAreaBytes, 8, nullptr, dcos::Visibility::Local);
        },
        [](size_t n) { return dcos::bufferPoolAgent.AddObjects(n); });
}

void deletePools()
{
    while (poolCount > 0) {
        (void)dcos::bufferPoolAgent.Delete(pools[--poolCount]);
    }
}

void addPoolSlots() { check(dcos::bufferPoolAgent.AddObjects(8)); }

// Heaps of the smallest size, one segment of the smallest size.
alignas(8) uint8_t heapAreas[kSmallPopulation][dcos::HeapAgent::SegmentBytes(1)];
ObjectId heaps[kSmallPopulation];
uint32_t heapCount = 0;

Status heapsWithRoom(uint32_t count)
{
    return createWithRoom(
        count, heaps, heapCount,
        [](uint32_t i) { return dcos::heapAgent.Create(heapAreas[i], sizeof heapAreas[i], nullptr, dcos::Visibility::Local); },
        [](size_t n) { return dcos::heapAgent.AddObjects(n); });
}

void deleteHeaps()
{
    while (heapCount > 0) {
        (void)dcos::heapAgent.Delete(heaps[--heapCount]);
    }
}

void addHeapSlots() { check(dcos::heapAgent.AddObjects(8)); }

// Message ports.
ObjectId ports[kSmallPopulation];
uint32_t portCount = 0;

Status portsWithRoom(uint32_t count)
{
    return createWithRoom(
        count, ports, portCount,
        [](uint32_t) { return dcos::messagePortAgent.Create(nullptr, dcos::Visibility::Local); },
        [](size_t n) { return dcos::messagePortAgent.AddObjects(n); });
}

void deletePorts()
{
    while (portCount > 0) {
        (void)dcos::messagePortAgent.Delete(ports[--portCount]);
    }
}

void addPortSlots() { check(dcos::messagePortAgent.AddObjects(8)); }

// Semaphores (binary, free).
ObjectId semaphores[kSmallPopulation];
uint32_t semaphoreCount = 0;

Status semaphoresWithRoom(uint32_t count)
{
    return createWithRoom(
        count, semaphores, semaphoreCount,
        [](uint32_t) { return dcos::semaphoreAgent.Create(dcos::SemaphoreAttributes{}); },
        [](size_t n) { return dcos::semaphoreAgent.AddObjects(n); });
}

void deleteSemaphores()
{
    while (semaphoreCount > 0) {
        (void)dcos::semaphoreAgent.Delete(semaphores[--semaphoreCount]);
    }
}

void addSemaphoreSlots() { check(dcos::semaphoreAgent.AddObjects(8)); }

// DSM publishers, and subscriptions to one publisher.
ObjectId publishers[kSmallPopulation];
uint32_t publisherCount = 0;
ObjectId subscriptions[kSmallPopulation];
uint32_t subscriptionCount = 0;

Status publishersWithRoom(uint32_t count)
{
    return createWithRoom(
        count, publishers, publisherCount,
        [](uint32_t) { return dcos::dsmAgent.Create(nullptr, dcos::Visibility::Local); },
        [](size_t n) { return dcos::dsmAgent.AddObjects(n); });
}

Status subscriptionsWithRoom(uint32_t count)
{
    const Status status = count <= kSmallPopulation ? publishersWithRoom(1) : Status::TableFull;
    if (status != Status::Ok) {
        return status;
    }
    return createWithRoom(
        count, subscriptions, subscriptionCount, [](uint32_t) { return dcos::dsmAgent.Open(publishers[0]); },
        [](size_t n) { return dcos::dsmAgent.AddSubscribers(n); });
}

void deleteDsmObjects()
{
    while (subscriptionCount > 0) {
        (void)dcos::dsmAgent.Close(subscriptions[--subscriptionCount]);
    }
    while (publisherCount > 0) {
        (void)dcos::dsmAgent.Delete(publishers[--publisherCount]);
    }
}

void addPublisherSlots() { check(dcos::dsmAgent.AddObjects(8)); }
void addSubscriptionSlots() { check(dcos::dsmAgent.AddSubscribers(8)); }

} // namespace

DCOS_BENCHMARK(bufferPoolAddObjectsBench, "BufferPool.AddObjects", poolsWithRoom, addPoolSlots, Cost::Variable,
               .teardown = deletePools);
DCOS_BENCHMARK(heapAddObjectsBench, "Heap.AddObjects", heapsWithRoom, addHeapSlots, Cost::Variable,
               .teardown = deleteHeaps);
DCOS_BENCHMARK(portAddObjectsBench, "Port.AddObjects", portsWithRoom, addPortSlots, Cost::Variable,
               .teardown = deletePorts);
DCOS_BENCHMARK(semaphoreAddObjectsBench, "Semaphore.AddObjects", semaphoresWithRoom, addSemaphoreSlots,
               Cost::Variable, .teardown = deleteSemaphores);
DCOS_BENCHMARK(dsmAddObjectsBench, "Dsm.AddObjects", publishersWithRoom, addPublisherSlots, Cost::Variable,
               .teardown = deleteDsmObjects);
DCOS_BENCHMARK(dsmAddSubscribersBench, "Dsm.AddSubscribers", subscriptionsWithRoom, addSubscriptionSlots,
               Cost::Variable, .teardown = deleteDsmObjects);
DCOS_BENCHMARK(taskAddObjectsBench, "Task.AddObjects", tasksWithRoom, addTaskSlots, Cost::Variable,
               .teardown = killTasks);
DCOS_BENCHMARK(timerAddObjectsBench, "Timer.AddObjects", timersWithRoom, addTimerSlots, Cost::Variable,
               .teardown = deleteTimers);
DCOS_BENCHMARK(systemAddObjectsBench, "System.AddObjects", devicesWithRoom, addDeviceSlots, Cost::Variable,
               .teardown = deleteDevices);

} // namespace bench
