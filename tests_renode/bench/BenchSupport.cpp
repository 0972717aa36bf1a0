// Populations of kernel objects for the agent benchmarks; see BenchSupport.hpp.
#include "BenchSupport.hpp"

#include <dcos/internal/TaskManager.hpp>

namespace bench {

namespace {

// Every task spawnTask created, oldest first. A slot set to null was killed
// or ended by itself.
dcos::ObjectId spawned[maximumObjectCount];
uint32_t spawnedCount = 0;

} // namespace

void blockForever(uintptr_t)
{
    for (;;) {
        (void)dcos::taskAgent.ReceiveEvent(kNeverPostedEvent, dcos::EventWait::All, dcos::kWaitForever);
    }
}

dcos::Result<dcos::ObjectId> spawnTask(dcos::TaskEntry entry, uint8_t priority, uintptr_t argument, const char* name,
                                       bool floatingPoint)
{
    if (spawnedCount == maximumObjectCount) {
        return dcos::Status::TableFull;
    }
    dcos::TaskAttributes attributes;
    attributes.name = name;
    attributes.priority = priority;
    attributes.stackSize = dcos::kMinimumStackSize;
    attributes.floatingPoint = floatingPoint;
    dcos::Result<dcos::ObjectId> id = dcos::taskAgent.Create(attributes, entry, argument);
    if (id.status() == dcos::Status::TableFull) {
        const dcos::Status grown = dcos::taskAgent.AddObjects(8);
        if (grown != dcos::Status::Ok) {
            return grown;
        }
        id = dcos::taskAgent.Create(attributes, entry, argument);
    }
    if (id.ok()) {
        spawned[spawnedCount++] = id.value();
    }
    return id;
}

dcos::Status fillTasks(uint32_t total, uint8_t priority, dcos::ObjectId* target)
{
    if (target != nullptr) {
        *target = dcos::ObjectId::null();
    }
    while (taskCount() < total) {
        const bool last = taskCount() + 1 == total;
        const dcos::Result<dcos::ObjectId> id = spawnTask(blockForever, priority, 0, last ? "target" : nullptr);
        if (!id.ok()) {
            return id.status();
        }
        if (last && target != nullptr) {
            *target = id.value();
        }
    }
    return dcos::Status::Ok;
}

void killTasks()
{
    // Newest first: each stack then joins the free block just below it, so
    // the stack arena's free list stays one block long.
    while (spawnedCount > 0) {
        const dcos::ObjectId id = spawned[--spawnedCount];
        if (!id.isNull()) {
            (void)dcos::taskAgent.KillTask(id);
        }
    }
}

void forgetTask(dcos::ObjectId task)
{
    for (uint32_t i = spawnedCount; i > 0; --i) {
        if (spawned[i - 1] == task) {
            spawned[i - 1] = dcos::ObjectId::null();
            break;
        }
    }
    while (spawnedCount > 0 && spawned[spawnedCount - 1].isNull()) {
        --spawnedCount;
    }
}

uint32_t taskCount() { return static_cast<uint32_t>(dcos::internal::TaskManager::taskCount()); }

dcos::ObjectId self() { return dcos::taskAgent.IdOfSelf(); }

uint8_t selfPriority() { return dcos::taskAgent.GetPriority(self()).value(); }

} // namespace bench
