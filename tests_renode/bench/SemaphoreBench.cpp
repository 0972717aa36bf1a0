// Benchmarks of the semaphore agent's primitives (seed 7.11, Table 9.10).
//
// The object count is the number of semaphores on the node, the kernel's
// own included (as for tasks); the rest are created by the shell: binary,
// free, priority-ordered waiters, no priority inheritance. The
// measured call acts on the newest, "target". Semaphore.AddObjects is in
// ConfigurationBench.cpp.
#include "BenchSupport.hpp"

#include <dcos/SemaphoreAgent.hpp>
#include <dcos/internal/SemaphoreManager.hpp>

namespace bench {
namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::semaphoreAgent;
using dcos::SemaphoreAttributes;
using dcos::SemaphoreKind;
using dcos::Status;

ObjectId semaphores[maximumObjectCount];
uint32_t createdCount = 0; // Semaphores this file created, oldest first.
ObjectId target;
volatile uint32_t lastValue;

SemaphoreAttributes binaryAttributes(const char* name)
{
    SemaphoreAttributes attributes;
    attributes.name = name;
    attributes.kind = SemaphoreKind::Binary;
    attributes.initialCount = 1;
    return attributes;
}

Result<ObjectId> createSemaphore(const SemaphoreAttributes& attributes)
{
    return createGrowing([&] { return semaphoreAgent.Create(attributes); }, semaphoreAgent.AddObjects);
}

// Creates semaphores until count exist on the node, the last one "target" with @p last's attributes.
Status populateWith(uint32_t count, const SemaphoreAttributes& last)
{
    while (dcos::internal::semaphoreCount() < count) {
        const bool isLast = dcos::internal::semaphoreCount() + 1 == count;
        const Result<ObjectId> id = createSemaphore(isLast ? last : binaryAttributes(nullptr));
        if (!id.ok()) {
            return id.status();
        }
        semaphores[createdCount++] = id.value();
        if (isLast) {
            target = id.value();
        }
    }
    return Status::Ok;
}

Status populate(uint32_t count) { return populateWith(count, binaryAttributes("target")); }

void clearAll()
{
    killTasks();
    while (createdCount > 0) {
        (void)semaphoreAgent.Delete(semaphores[--createdCount]);
    }
    target = ObjectId::null();
}

// --- Semaphore.Create: one more binary semaphore with N - 1; deleted again.

ObjectId created;

Status populateButOne(uint32_t count) { return populate(count - 1); }

void createOneSemaphore()
{
    const Result<ObjectId> id = semaphoreAgent.Create(binaryAttributes(nullptr));
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void deleteCreated() { (void)semaphoreAgent.Delete(created); }

// --- Semaphore.Delete of the free target (no waiter); re-created unmeasured.

void deleteTarget() { check(semaphoreAgent.Delete(target)); }

void recreateTarget()
{
    const Result<ObjectId> id = createSemaphore(binaryAttributes("target"));
    target = id.ok() ? id.value() : ObjectId::null();
    semaphores[createdCount - 1] = target;
}

// --- Semaphore.Acquire ("available/polling") of the free target, and
// Semaphore.Release of the target the shell holds, with no waiter.

void acquire() { check(semaphoreAgent.Acquire(target, dcos::kPoll)); }
void release() { check(semaphoreAgent.Release(target)); }
void acquireAgain() { (void)semaphoreAgent.Acquire(target, dcos::kPoll); }
void releaseAgain() { (void)semaphoreAgent.Release(target); }

Status populateHeld(uint32_t count)
{
    const Status status = populate(count);
    return status != Status::Ok ? status : semaphoreAgent.Acquire(target, dcos::kPoll);
}

// --- Semaphore.AcquireWaiting: the target is a counting semaphore at 0, so
// the shell blocks in Acquire. Self-timed from the call to the first
// instruction of the partner (below the shell's priority) that runs
// instead; the partner then releases a unit, which goes straight to the
// waiting shell. (A counting semaphore, because any task may release one;
// the wait path is the same for both kinds.)

void markThenRelease(uintptr_t)
{
    for (;;) {
        markEnd();
        (void)semaphoreAgent.Release(target);
    }
}

Status populateWithReleasingPartner(uint32_t count)
{
    SemaphoreAttributes counting = binaryAttributes("target");
    counting.kind = SemaphoreKind::Counting;
    counting.initialCount = 0;
    const Status status = populateWith(count, counting);
    if (status != Status::Ok) {
        return status;
    }
    const Result<ObjectId> id = spawnTask(markThenRelease, static_cast<uint8_t>(selfPriority() + 1));
    return id.status();
}

void acquireBlocking()
{
    markStart();
    (void)semaphoreAgent.Acquire(target, dcos::kWaitForever);
}

// --- Semaphore.XferOwnership of the target from the shell to the shell.

void transferOwnership() { check(semaphoreAgent.XferOwnership(target, self())); }

// --- Semaphore.NameToObject (configuration): the newest semaphore, "target".

void nameToObject()
{
    const Result<ObjectId> id = semaphoreAgent.NameToObject("target");
    check(id.status());
    lastValue = id.ok() ? id.value().raw() : 0;
}

} // namespace

DCOS_BENCHMARK(semaphoreCreateBench, "Semaphore.Create", populateButOne, createOneSemaphore, Cost::Constant,
               .restore = deleteCreated, .teardown = clearAll);
DCOS_BENCHMARK(semaphoreDeleteBench, "Semaphore.Delete", populate, deleteTarget, Cost::Constant,
               .restore = recreateTarget, .teardown = clearAll);
DCOS_BENCHMARK(semaphoreAcquireBench, "Semaphore.Acquire", populate, acquire, Cost::Constant,
               .restore = releaseAgain, .teardown = clearAll);
DCOS_BENCHMARK(semaphoreReleaseBench, "Semaphore.Release", populateHeld, release, Cost::Constant,
               .restore = acquireAgain, .teardown = clearAll);
DCOS_BENCHMARK(semaphoreAcquireWaitingBench, "Semaphore.AcquireWaiting", populateWithReleasingPartner,
               acquireBlocking, Cost::Constant, .teardown = clearAll, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(semaphoreXferOwnershipBench, "Semaphore.XferOwnership", populate, transferOwnership, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(semaphoreNameToObjectBench, "Semaphore.NameToObject", populate, nameToObject, Cost::Variable,
               .teardown = clearAll);

} // namespace bench
