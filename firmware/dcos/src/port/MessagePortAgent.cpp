// The message port agent (seed 7.9): its interface object and kernel side.
//
// Ports sit in a static array beside their object table, as timers do. Each
// port holds its message queue (32 levels under a bitmap, MessageQueue) and
// the wait queue of its receiver, so the whole state of a pending Receive
// lives in the port, where a request arriving from the network can drive it
// later. Messages are copied into buffers of one kernel area shared by all
// ports (MessageBufferPool), which AddMsgBufs extends from a static reserve.
//
// Every service runs with interrupts disabled (arch_x86::InterruptGuard) on
// this uniprocessor; the longest stretch is a 16-byte copy and a constant
// number of list operations, so Send and Receive cost O(1).
//
// Ownership rules: any task or interrupt handler may Send; only the owner
// receives, so a port has exactly one receiver (N-to-1) and the owner cannot
// give the port away while it waits in Receive; the owner or a super user may
// Delete; only the owner transfers ownership.
#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/FastPath.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/MessageBufferPool.hpp>
#include <dcos/internal/MessageQueue.hpp>
#include <dcos/internal/ObjectTable.hpp>
#include <dcos/internal/PortManager.hpp>
#include <dcos/internal/ResourceRecovery.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/WaitQueue.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos::internal {

namespace {

// A message port. Its receiver waits in receivers with Task::waitData
// pointing at the Message it receives into; Send copies straight there.
struct PortObject {
    ObjectId id;
    bool dying = false; ///< Being deleted: refused as stale while its receiver is woken.
    MessageQueue queue;
    WaitQueue receivers{WaitQueue::Order::Priority};
};

ObjectTable<PortObject*, kPortCapacity, TaskOwnerKeys> portTable(ObjectType::MessagePort, 0);
PortObject ports[kPortCapacity];
MessageBuffer bufferReserve[kMessageBufferCapacity];
MessageBufferPool bufferPool(bufferReserve, kMessageBufferCapacity);
bool started = false;

size_t portSlotOf(ObjectId id) { return portTable.slotNumber(id); }

// Activates the boot-time slots and buffers, and takes the board's node id,
// on the first call to the agent (the board knows its node only once it is
// initialised). Interrupts are disabled by the caller.
void start()
{
    if (!started) {
        // Cannot fail: the table and the area are empty, and KernelConfig
        // proves the boot counts fit.
        (void)portTable.setNode(localNode());
        (void)portTable.AddObjects(kPortsActiveAtBoot);
        (void)bufferPool.AddMsgBufs(kMessageBuffersActiveAtBoot);
        started = true;
    }
}

// Resolves a port id: InvalidId for null or forged ids, Remote for another
// node's port, WrongType and StaleId from the table.
Result<PortObject*> resolvePort(ObjectId id)
{
    const Result<PortObject**> entry = portTable.resolve(id);
    if (!entry.ok()) {
        return entry.status();
    }
    if ((*entry.value())->dying) {
        return Status::StaleId;
    }
    return *entry.value();
}

// Hands the queued buffers back, wakes the receiver with Deleted and frees
// the slot. O(1): the queue returns its 32 levels as whole chains.
//
// A woken receiver more urgent than the caller runs at once, in the middle
// of this function, and may call the agent again. The port is therefore
// marked dying first, so every id to it is already refused as stale, and
// its slot is freed last, so no new port can take it while waking is under
// way.
void destroy(PortObject& port, ObjectId id)
{
    port.dying = true;
    port.queue.clear(bufferPool);
    TaskManager::wakeAll(port.receivers, Status::Deleted);
    port.id = ObjectId::null();
    port.dying = false;
    (void)portTable.Delete(id);
}

unsigned recoverPorts(ObjectId deadTask)
{
    arch_x86::InterruptGuard guard;
    start();
    return static_cast<unsigned>(
        portTable.forEachOwnedBy(deadTask, [](ObjectId id, PortObject*& port) { destroy(*port, id); }));
}

} // namespace

size_t PortManager::activeCount()
{
    arch_x86::InterruptGuard guard;
    start();
    return portTable.activeCount();
}

size_t PortManager::portCount()
{
    arch_x86::InterruptGuard guard;
    start();
    return portTable.usedCount();
}

// Cold: only the console's port listing reads it.
[[gnu::cold]] bool PortManager::snapshot(size_t slot, PortInfo& info)
{
    arch_x86::InterruptGuard guard;
    start();
    if (slot >= portTable.activeCount() || ports[slot].id.isNull()) {
        return false;
    }
    const PortObject& port = ports[slot];
    info.id = port.id;
    info.owner = portTable.ownerOf(port.id).value();
    const char* name = portTable.nameOf(port.id).value();
    size_t i = 0;
    for (; i + 1 < sizeof info.name && name[i] != '\0'; ++i) {
        info.name[i] = name[i];
    }
    info.name[i] = '\0';
    info.order = port.queue.order();
    info.queued = port.queue.count();
    info.levelBits = port.queue.levelBits();
    info.receiverWaiting = !port.receivers.isEmpty();
    return true;
}

Result<ObjectId> PortManager::nameToObject(const char* name, Visibility askingScope)
{
    arch_x86::InterruptGuard guard;
    start();
    return portTable.NameToObject(name, askingScope);
}

MessageBufferCounts PortManager::bufferCounts()
{
    arch_x86::InterruptGuard guard;
    start();
    return MessageBufferCounts{bufferPool.freeCount(), bufferPool.activeCount(), bufferPool.capacity()};
}

DCOS_RESOURCE_RECOVERY(portRecovery, "message port", recoverPorts);

ObjectTableView messagePortTableView()
{
    return portTable.view();
}

} // namespace dcos::internal

namespace dcos {

using internal::bufferPool;
using internal::MessageBuffer;
using internal::MessageQueue;
using internal::PortObject;
using internal::portTable;
using internal::resolvePort;
using internal::start;
using internal::TaskManager;

namespace {

// The complete Send and Receive: every case, from a resolved id. The
// agent's fast paths (below) come here for all they do not handle.
Status sendLocal(ObjectId id, const Message& message, int priority);

[[gnu::noinline]] Status sendFull(ObjectId id, const Message& message, int priority)
{
    if (!MessageQueue::isValidPriority(priority)) {
        return Status::InvalidArgument;
    }
    const Status status = sendLocal(id, message, priority);
    // Another node's port: the request goes over the network and blocks the
    // caller, so it is made after the local attempt has let interrupts in.
    return internal::orRemotePortSend(status, id, message, priority);
}

Status sendLocal(ObjectId id, const Message& message, int priority)
{
    arch_x86::InterruptGuard guard;
    start();
    const Result<PortObject*> resolved = resolvePort(id);
    if (!resolved.ok()) {
        return resolved.status();
    }
    PortObject& port = *resolved.value();
    if (!port.receivers.isEmpty()) {
        // A receiver waits only while the queue is empty, so this message is
        // the one it gets: hand it over without taking a buffer.
        internal::Task& receiver = port.receivers.first();
        *reinterpret_cast<Message*>(receiver.waitData) = message;
        TaskManager::wakeFirst(port.receivers, Status::Ok);
        return Status::Ok;
    }
    MessageBuffer* buffer = bufferPool.take();
    if (buffer == nullptr) {
        return Status::NoMemory; // Refused, not dropped: the sender decides.
    }
    buffer->message = message; // A REP MOVSL: the destination is aligned.
    port.queue.post(*buffer, priority);
    return Status::Ok;
}

[[gnu::noinline]] Status receiveFull(ObjectId id, Message* into, const uint64_t* timeout)
{
    const uint64_t timeoutNs = *timeout;
    Message& message = *into;
    arch_x86::InterruptGuard guard;
    start();
    const Result<PortObject*> resolved = resolvePort(id);
    if (!resolved.ok()) {
        // Another node's port has its owner there, the only one who receives.
        return resolved.status() == Status::Remote ? Status::NotOwner : resolved.status();
    }
    const Status owner = portTable.checkOwner(id, internal::currentTaskId());
    if (owner != Status::Ok) {
        return owner; // N-to-1: the owner is the only receiver, super user or not.
    }
    PortObject& port = *resolved.value();
    if (MessageBuffer* buffer = port.queue.takeFirst()) {
        internal::copySixteenBytes(message.bytes, buffer->message.bytes);
        bufferPool.give(*buffer);
        return Status::Ok;
    }
    if (timeoutNs == kPoll) {
        return Status::WouldBlock;
    }
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    internal::Scheduler::current().waitData = reinterpret_cast<uintptr_t>(&message);
    return TaskManager::blockOn(port.receivers, timeoutNs);
}

} // namespace

DCOS_CONFIGURATION_SERVICE Result<ObjectId> MessagePortAgent::Create(const char* name, Visibility visibility, PortOrder order)
{
    if (order != PortOrder::Priority && order != PortOrder::Fifo) {
        return Status::InvalidArgument;
    }
    if (internal::inInterruptContext()) {
        return Status::InInterrupt; // The port would belong to whichever task was interrupted.
    }
    arch_x86::InterruptGuard guard;
    start();
    const Result<ObjectId> id = portTable.Create(internal::currentTaskId(), name, visibility);
    if (!id.ok()) {
        return id.status();
    }
    PortObject& port = internal::ports[internal::portSlotOf(id.value())];
    port.id = id.value();
    port.queue.reset(order);
    *portTable.resolve(id.value()).value() = &port;
    return id.value();
}

DCOS_CONFIGURATION_SERVICE Status MessagePortAgent::Delete(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    start();
    const Result<PortObject*> port = resolvePort(id);
    if (!port.ok()) {
        return port.status();
    }
    const Status owner =
        portTable.checkOwnerOrPrivileged(id, internal::currentTaskId(), internal::currentTaskIsSuperUser());
    if (owner != Status::Ok) {
        return owner;
    }
    internal::destroy(*port.value(), id);
    return Status::Ok;
}

Status MessagePortAgent::Send(ObjectId id, const Message& message, int priority)
{
    // The fast path queues a message on a live port no receiver waits at;
    // a hand-over to a waiting receiver, an error or a wrong id goes the full way.
    if (MessageQueue::isValidPriority(priority)) [[likely]] {
        arch_x86::InterruptGuard guard;
        PortObject* const* found = portTable.find(id);
        if (found != nullptr && !(*found)->dying && (*found)->receivers.isEmpty()) [[likely]] {
            if (MessageBuffer* buffer = bufferPool.take()) [[likely]] {
                buffer->message = message; // A REP MOVSL: the destination is aligned.
                (*found)->queue.post(*buffer, priority);
                return Status::Ok;
            }
        }
    }
    return sendFull(id, message, priority);
}

Status MessagePortAgent::Receive(ObjectId id, Message& message, uint64_t timeoutNs)
{
    // The fast path takes a queued message for the port's owner; an empty
    // queue (a wait), an error or a wrong id goes the full way.
    {
        arch_x86::InterruptGuard guard;
        ObjectId owner;
        PortObject* const* found = portTable.find(id, owner);
        if (found != nullptr && !(*found)->dying && internal::Scheduler::started()
            && owner == internal::Scheduler::current().id) [[likely]] {
            if (MessageBuffer* buffer = (*found)->queue.takeFirst()) {
                internal::copySixteenBytes(message.bytes, buffer->message.bytes);
                bufferPool.give(*buffer);
                return Status::Ok;
            }
        }
    }
    return internal::callSlowPath(receiveFull, id, &message, &timeoutNs);
}

DCOS_CONFIGURATION_SERVICE Status MessagePortAgent::AddMsgBufs(size_t count)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    start();
    return bufferPool.AddMsgBufs(count);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> MessagePortAgent::NameToObject(const char* name)
{
    return internal::orRemoteName(internal::PortManager::nameToObject(name, Visibility::Local),
                                  ObjectType::MessagePort, name);
}

DCOS_CONFIGURATION_SERVICE Status MessagePortAgent::AddObjects(size_t count)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    start();
    return portTable.AddObjects(count);
}

DCOS_CONFIGURATION_SERVICE Status MessagePortAgent::XferOwnership(ObjectId id, ObjectId newOwner)
{
    const Status newOwnerStatus = TaskManager::checkNewOwner(newOwner);
    if (newOwnerStatus != Status::Ok) {
        return newOwnerStatus;
    }
    arch_x86::InterruptGuard guard;
    start();
    const Result<PortObject*> port = resolvePort(id);
    if (!port.ok()) {
        return port.status();
    }
    return portTable.XferOwnership(id, internal::currentTaskId(), newOwner);
}

} // namespace dcos
