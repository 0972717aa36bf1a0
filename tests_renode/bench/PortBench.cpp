// Benchmarks of the message port agent's primitives (seed 7.9, Table 9.9;
// the seed's PortAgent, so the names are "Port.*").
//
// The object count is the number of ports, all created and owned by the
// shell, priority ordered. Every port but the newest, "target", holds one
// queued message (level 7), so with 4096 ports 4095 message buffers are in
// use; the measured call acts on the target, which is empty unless the
// benchmark says otherwise. Port.AddObjects is in ConfigurationBench.cpp.
#include "BenchSupport.hpp"

#include <dcos/MessagePortAgent.hpp>
#include <dcos/internal/PortManager.hpp>

namespace bench {
namespace {

using dcos::Message;
using dcos::messagePortAgent;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

constexpr int kFillerLevel = 7;
constexpr int kMeasuredLevel = 5;

ObjectId ports[maximumObjectCount];
uint32_t portCount = 0;
ObjectId target;
ObjectId partner;
Message message{{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16}};
Message received;
volatile uint32_t lastValue;

Result<ObjectId> createPort(const char* name)
{
    Result<ObjectId> id = messagePortAgent.Create(name, dcos::Visibility::Local);
    if (id.status() == Status::TableFull) {
        const Status grown = messagePortAgent.AddObjects(8);
        if (grown != Status::Ok) {
            return grown;
        }
        id = messagePortAgent.Create(name, dcos::Visibility::Local);
    }
    return id;
}

// Makes sure at least count message buffers are free, activating more of
// the reserve (which never shrinks) when needed.
Status reserveBuffers(size_t count)
{
    const dcos::internal::MessageBufferCounts counts = dcos::internal::PortManager::bufferCounts();
    return counts.free >= count ? Status::Ok : messagePortAgent.AddMsgBufs(count - counts.free);
}

// Creates ports until count exist; all but the last, "target", get a message.
Status populate(uint32_t count)
{
    const Status reserved = reserveBuffers(count + 8);
    if (reserved != Status::Ok) {
        return reserved;
    }
    while (portCount < count) {
        const bool last = portCount + 1 == count;
        const Result<ObjectId> id = createPort(last ? "target" : nullptr);
        if (!id.ok()) {
            return id.status();
        }
        ports[portCount++] = id.value();
        if (last) {
            target = id.value();
        } else {
            const Status sent = messagePortAgent.Send(id.value(), message, kFillerLevel);
            if (sent != Status::Ok) {
                return sent;
            }
        }
    }
    return Status::Ok;
}

void clearAll()
{
    killTasks();
    // Delete discards the queued messages; their buffers go back to the free area.
    while (portCount > 0) {
        (void)messagePortAgent.Delete(ports[--portCount]);
    }
    target = ObjectId::null();
    partner = ObjectId::null();
}

// --- Port.Create: one more port with N - 1; deleted again.

ObjectId created;

Status populateButOne(uint32_t count) { return populate(count - 1); }

void createOnePort()
{
    const Result<ObjectId> id = messagePortAgent.Create(nullptr, dcos::Visibility::Local);
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void deleteCreated() { (void)messagePortAgent.Delete(created); }

// --- Port.Delete of the empty target; re-created unmeasured.

void deleteTarget() { check(messagePortAgent.Delete(target)); }

void recreateTarget()
{
    const Result<ObjectId> id = createPort("target");
    target = id.ok() ? id.value() : ObjectId::null();
    ports[portCount - 1] = target;
}

// --- Port.Send to the empty target, no receiver waiting: a buffer is taken
// and queued at level 5. Received again, unmeasured.

void send() { check(messagePortAgent.Send(target, message, kMeasuredLevel)); }

void receiveQueued() { (void)messagePortAgent.Receive(target, received, dcos::kPoll); }

// --- Port.Receive ("available/polling"): the target holds one message.

Status populateWithMessage(uint32_t count)
{
    const Status status = populate(count);
    return status != Status::Ok ? status : messagePortAgent.Send(target, message, kMeasuredLevel);
}

void receiveAvailable() { check(messagePortAgent.Receive(target, received, dcos::kPoll)); }

void sendAgain() { (void)messagePortAgent.Send(target, message, kMeasuredLevel); }

// --- Port.ReceiveWaiting: the target is empty, so the shell blocks in
// Receive. Self-timed from the call to the first instruction of the partner
// (below the shell's priority) that runs instead; the partner then sends,
// which hands the message straight to the waiting shell.

void markThenSend(uintptr_t)
{
    for (;;) {
        markEnd();
        (void)messagePortAgent.Send(target, message, kMeasuredLevel);
    }
}

Status populateWithSendingPartner(uint32_t count)
{
    const Status status = populate(count);
    if (status != Status::Ok) {
        return status;
    }
    const Result<ObjectId> id = spawnTask(markThenSend, static_cast<uint8_t>(selfPriority() + 1));
    partner = id.ok() ? id.value() : ObjectId::null();
    return id.status();
}

void receiveBlocking()
{
    markStart();
    (void)messagePortAgent.Receive(target, received, dcos::kWaitForever);
}

// --- Port.AddMsgBufs (configuration, variable): eight more buffers of the
// reserve per call; a buffer never goes back to the reserve.

void addMessageBuffers() { check(messagePortAgent.AddMsgBufs(8)); }

// --- Port.XferOwnership of the target from the shell to the shell.

void transferOwnership() { check(messagePortAgent.XferOwnership(target, self())); }

// --- Port.NameToObject (configuration): the newest port, "target".

void nameToObject()
{
    const Result<ObjectId> id = messagePortAgent.NameToObject("target");
    check(id.status());
    lastValue = id.ok() ? id.value().raw() : 0;
}

} // namespace

DCOS_BENCHMARK(portCreateBench, "Port.Create", populateButOne, createOnePort, Cost::Constant,
               .restore = deleteCreated, .teardown = clearAll);
DCOS_BENCHMARK(portDeleteBench, "Port.Delete", populate, deleteTarget, Cost::Constant, .restore = recreateTarget,
               .teardown = clearAll);
DCOS_BENCHMARK(portSendBench, "Port.Send", populate, send, Cost::Constant, .restore = receiveQueued,
               .teardown = clearAll);
DCOS_BENCHMARK(portReceiveBench, "Port.Receive", populateWithMessage, receiveAvailable, Cost::Constant,
               .restore = sendAgain, .teardown = clearAll);
DCOS_BENCHMARK(portReceiveWaitingBench, "Port.ReceiveWaiting", populateWithSendingPartner, receiveBlocking,
               Cost::Constant, .teardown = clearAll, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(portAddMsgBufsBench, "Port.AddMsgBufs", populate, addMessageBuffers, Cost::Variable,
               .teardown = clearAll);
DCOS_BENCHMARK(portXferOwnershipBench, "Port.XferOwnership", populate, transferOwnership, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(portNameToObjectBench, "Port.NameToObject", populate, nameToObject, Cost::Variable,
               .teardown = clearAll);

} // namespace bench
