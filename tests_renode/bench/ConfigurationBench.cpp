// Benchmarks of the AddObjects configuration service of the task, timer and
// system agents (seed Tables 9.2, 9.4, 9.5; "Variable": O(count)).
//
// AddObjects activates eight more slots of a table per call, and a table
// never gives slots back, so these benchmarks need tables that earlier
// benchmarks have not fully activated: mk/bench.mk links this file before
// every benchmark that fills a table. With 4096 objects a table is full by
// definition (4096 is the capacity, the 12-bit index limit), so the
// 4096-object figure is refused with "object table full".
#include "BenchSupport.hpp"

#include <dcos/Device.hpp>
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
        dcos::timerAgent.Delete(timers[--timerCount]);
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
        dcos::systemAgent.Delete(devices[--deviceCount]);
    }
}

void addDeviceSlots() { check(dcos::systemAgent.AddObjects(8)); }

} // namespace

DCOS_BENCHMARK(taskAddObjectsBench, "Task.AddObjects", tasksWithRoom, addTaskSlots, Cost::Variable,
               .teardown = killTasks);
DCOS_BENCHMARK(timerAddObjectsBench, "Timer.AddObjects", timersWithRoom, addTimerSlots, Cost::Variable,
               .teardown = deleteTimers);
DCOS_BENCHMARK(systemAddObjectsBench, "System.AddObjects", devicesWithRoom, addDeviceSlots, Cost::Variable,
               .teardown = deleteDevices);

} // namespace bench
