// The hook between the agents' miss paths and the remote agent (RemoteForward.hpp).
#include <dcos/internal/RemoteForward.hpp>

namespace dcos::internal {

namespace {

// Written once, by the remote agent's start in task context, before any
// link delivers a frame; an aligned pointer store is atomic on x86.
RemoteForwarder remoteForwarder = nullptr;
RemoteNameResolver remoteNameResolver = nullptr;
RemotePortSender remotePortSender = nullptr;

} // namespace

void setRemoteForwarder(RemoteForwarder forwarder) { remoteForwarder = forwarder; }

void setRemoteNameResolver(RemoteNameResolver resolver) { remoteNameResolver = resolver; }

void setRemotePortSender(RemotePortSender sender) { remotePortSender = sender; }

namespace {
RemoteAlarmSetter remoteAlarmSetter = nullptr;
RemoteAlarmQueue remoteAlarmQueue = nullptr;
} // namespace

void setRemoteAlarmSetter(RemoteAlarmSetter setter) { remoteAlarmSetter = setter; }

Status forwardRemoteAlarm(ObjectId timer, RemoteAlarmKind kind, const AlarmNotification& notification,
                          uint64_t timeNs)
{
    RemoteAlarmSetter const setter = remoteAlarmSetter;
    if (setter == nullptr) {
        return Status::Remote;
    }
    return setter(timer, kind, notification, timeNs);
}

void setRemoteAlarmQueue(RemoteAlarmQueue queue) { remoteAlarmQueue = queue; }

void queueRemoteAlarm(ObjectId timer, ObjectId owner, const AlarmNotification& notification)
{
    RemoteAlarmQueue const queue = remoteAlarmQueue;
    if (queue != nullptr) {
        queue(timer, owner, notification);
    }
}

Status forwardRemotePortSend(ObjectId port, const Message& message, int priority)
{
    RemotePortSender const sender = remotePortSender;
    if (sender == nullptr) {
        return Status::Remote;
    }
    return sender(port, message, priority);
}

Result<ObjectId> remoteNameToObject(ObjectType type, const char* name)
{
    RemoteNameResolver const resolver = remoteNameResolver;
    if (resolver == nullptr) {
        return Status::NotFound;
    }
    return resolver(type, name);
}

Result<void*> forwardRemoteAllocate(RemoteService service, ObjectId id, uint32_t argument)
{
    const Result<uint32_t> reply = forwardRemote(service, id, argument);
    if (!reply.ok()) {
        return reply.status();
    }
    // Both nodes map all of the board's memory at the same addresses, so the
    // serving node's address is this node's pointer.
    return reinterpret_cast<void*>(static_cast<uintptr_t>(reply.value()));
}

Status forwardRemoteReturn(RemoteService service, ObjectId id, const void* address)
{
    const uintptr_t value = reinterpret_cast<uintptr_t>(address);
    if (value > 0xFFFFFFFFu) {
        return Status::InvalidArgument; // Not an address of a 32-bit node's memory (a host build's pointer).
    }
    return forwardRemote(service, id, static_cast<uint32_t>(value)).status();
}

Result<uint32_t> forwardRemote(RemoteService service, ObjectId id, uint32_t argument)
{
    RemoteForwarder const forwarder = remoteForwarder;
    if (forwarder == nullptr) {
        return Status::Remote;
    }
    return forwarder(service, id, argument);
}

} // namespace dcos::internal
