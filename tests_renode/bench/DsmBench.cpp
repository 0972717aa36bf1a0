// Benchmarks of the distributed shared memory agent's local primitives
// (seed 7.10, Table 9.8; the seed's DSMemAgent, so the names are "Dsm.*").
//
// The object count is the number of publishers, all created by the shell,
// and as many subscriptions, one to each publisher, opened by the shell.
// Every publisher has been written once. The measured call acts on the
// newest publisher, "target", or on the subscription to it. Dsm.AddObjects
// and Dsm.AddSubscribers are in ConfigurationBench.cpp.
#include "BenchSupport.hpp"

#include <dcos/DsmAgent.hpp>

namespace bench {
namespace {

using dcos::DsmPage;
using dcos::dsmAgent;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

ObjectId publishers[maximumObjectCount];
ObjectId subscriptions[maximumObjectCount];
uint32_t publisherCount = 0;
uint32_t subscriptionCount = 0;
ObjectId target;
ObjectId targetSubscription;
DsmPage page{{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16}};
DsmPage readPage;
uint32_t lastSeen = dcos::kNoDsmData;
volatile uint32_t lastValue;

Result<ObjectId> createPublisher(const char* name)
{
    Result<ObjectId> id = dsmAgent.Create(name, dcos::Visibility::Local);
    if (id.status() == Status::TableFull) {
        const Status grown = dsmAgent.AddObjects(8);
        if (grown != Status::Ok) {
            return grown;
        }
        id = dsmAgent.Create(name, dcos::Visibility::Local);
    }
    return id;
}

Result<ObjectId> openSubscription(ObjectId publisher)
{
    Result<ObjectId> id = dsmAgent.Open(publisher);
    if (id.status() == Status::TableFull) {
        const Status grown = dsmAgent.AddSubscribers(8);
        if (grown != Status::Ok) {
            return grown;
        }
        id = dsmAgent.Open(publisher);
    }
    return id;
}

// Creates publishers until count exist, each written once, the last one
// "target"; then opens subscriptions to them until subscribed exist.
Status populateWith(uint32_t count, uint32_t subscribed)
{
    while (publisherCount < count) {
        const bool last = publisherCount + 1 == count;
        const Result<ObjectId> id = createPublisher(last ? "target" : nullptr);
        if (!id.ok()) {
            return id.status();
        }
        publishers[publisherCount++] = id.value();
        if (last) {
            target = id.value();
        }
        const Result<uint32_t> written = dsmAgent.Write(id.value(), page);
        if (!written.ok()) {
            return written.status();
        }
    }
    while (subscriptionCount < subscribed) {
        const Result<ObjectId> id = openSubscription(publishers[subscriptionCount]);
        if (!id.ok()) {
            return id.status();
        }
        subscriptions[subscriptionCount++] = id.value();
    }
    targetSubscription = subscribed == count ? subscriptions[count - 1] : ObjectId::null();
    return Status::Ok;
}

Status populate(uint32_t count) { return populateWith(count, count); }

void clearAll()
{
    killTasks(); // Recovery deletes a publisher handed to a partner; its Delete below then fails harmlessly.
    while (subscriptionCount > 0) {
        (void)dsmAgent.Close(subscriptions[--subscriptionCount]);
    }
    while (publisherCount > 0) {
        (void)dsmAgent.Delete(publishers[--publisherCount]);
    }
    target = ObjectId::null();
    targetSubscription = ObjectId::null();
    lastSeen = dcos::kNoDsmData;
}

// --- Dsm.Create: one more publisher with N - 1 (and N - 1 subscriptions); deleted again.

ObjectId created;

Status populateButOne(uint32_t count) { return populate(count - 1); }

void createOnePublisher()
{
    const Result<ObjectId> id = dsmAgent.Create(nullptr, dcos::Visibility::Local);
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void deleteCreated() { (void)dsmAgent.Delete(created); }

// --- Dsm.Delete of the target, with no subscription to it and no reader
// waiting; re-created unmeasured.

Status populateUnsubscribedTarget(uint32_t count) { return populateWith(count, count - 1); }

void deleteTarget() { check(dsmAgent.Delete(target)); }

void recreateTarget()
{
    const Result<ObjectId> id = createPublisher("target");
    target = id.ok() ? id.value() : ObjectId::null();
    publishers[publisherCount - 1] = target;
}

// --- Dsm.Open of a subscription to the target (N - 1 open); closed again.

void openToTarget()
{
    const Result<ObjectId> id = dsmAgent.Open(target);
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void closeCreated() { (void)dsmAgent.Close(created); }

// --- Dsm.Close of the subscription to the target; re-opened unmeasured.

void closeTargetSubscription() { check(dsmAgent.Close(targetSubscription)); }

void reopenTargetSubscription()
{
    const Result<ObjectId> id = dsmAgent.Open(target);
    targetSubscription = id.ok() ? id.value() : ObjectId::null();
    subscriptions[subscriptionCount - 1] = targetSubscription;
}

// --- Dsm.Write of the target, no reader waiting.

void write()
{
    const Result<uint32_t> written = dsmAgent.Write(target, page);
    check(written.status());
    lastValue = written.ok() ? written.value() : 0;
}

// --- Dsm.Read ("available/polling"): the target has data newer than the
// caller has seen (it passes kNoDsmData), so Read copies the page at once.

void readAvailable()
{
    const Result<uint32_t> read = dsmAgent.Read(targetSubscription, dcos::kNoDsmData, readPage, dcos::kPoll);
    check(read.status());
    lastValue = read.ok() ? read.value() : 0;
}

// --- Dsm.ReadWaiting: the shell has seen the target's latest data, so it
// blocks in Read. Self-timed from the call to the first instruction of the
// partner (below the shell's priority) that runs instead; the partner, the
// target's owner and so its single writer, then writes, which hands the
// page to the waiting shell.

void markThenWrite(uintptr_t)
{
    for (;;) {
        markEnd();
        (void)dsmAgent.Write(target, page);
    }
}

Status populateWithWritingPartner(uint32_t count)
{
    const Status status = populate(count);
    if (status != Status::Ok) {
        return status;
    }
    const Result<ObjectId> id = spawnTask(markThenWrite, static_cast<uint8_t>(selfPriority() + 1));
    if (!id.ok()) {
        return id.status();
    }
    const Result<uint32_t> read = dsmAgent.Read(targetSubscription, dcos::kNoDsmData, readPage, dcos::kPoll);
    lastSeen = read.ok() ? read.value() : dcos::kNoDsmData;
    return dsmAgent.XferOwnership(target, id.value());
}

void readBlocking()
{
    markStart();
    const Result<uint32_t> read = dsmAgent.Read(targetSubscription, lastSeen, readPage, dcos::kWaitForever);
    lastSeen = read.ok() ? read.value() : lastSeen;
}

// --- Dsm.XferOwnership of the target publisher from the shell to the shell.

void transferOwnership() { check(dsmAgent.XferOwnership(target, self())); }

// --- Dsm.NameToObject (configuration): the newest publisher, "target".

void nameToObject()
{
    const Result<ObjectId> id = dsmAgent.NameToObject("target");
    check(id.status());
    lastValue = id.ok() ? id.value().raw() : 0;
}

} // namespace

DCOS_BENCHMARK(dsmCreateBench, "Dsm.Create", populateButOne, createOnePublisher, Cost::Constant,
               .restore = deleteCreated, .teardown = clearAll);
DCOS_BENCHMARK(dsmDeleteBench, "Dsm.Delete", populateUnsubscribedTarget, deleteTarget, Cost::Constant,
               .restore = recreateTarget, .teardown = clearAll);
DCOS_BENCHMARK(dsmOpenBench, "Dsm.Open", populateUnsubscribedTarget, openToTarget, Cost::Constant,
               .restore = closeCreated, .teardown = clearAll);
DCOS_BENCHMARK(dsmCloseBench, "Dsm.Close", populate, closeTargetSubscription, Cost::Constant,
               .restore = reopenTargetSubscription, .teardown = clearAll);
DCOS_BENCHMARK(dsmWriteBench, "Dsm.Write", populate, write, Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(dsmReadBench, "Dsm.Read", populate, readAvailable, Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(dsmReadWaitingBench, "Dsm.ReadWaiting", populateWithWritingPartner, readBlocking, Cost::Constant,
               .teardown = clearAll, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(dsmXferOwnershipBench, "Dsm.XferOwnership", populate, transferOwnership, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(dsmNameToObjectBench, "Dsm.NameToObject", populate, nameToObject, Cost::Variable,
               .teardown = clearAll);

} // namespace bench
