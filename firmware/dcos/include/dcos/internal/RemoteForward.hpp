// The one place where a primitive turns remote (seed 6.4).
//
// Whether an id is local is decided once, by the object tables' miss path
// (ObjectTableCore::missReason): an id of another node misses every table
// and comes back as Status::Remote, so the local fast paths pay nothing for
// distribution. The agents hand such an id, the service and its argument to
// forwardRemote, which gives it to the remote agent (RemoteAgent.hpp) when
// the full kernel has one running, and answers Remote (no network is up)
// otherwise: the minimal kernel links no remote agent.
#pragma once

#include <dcos/MessagePortAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/Status.hpp>
#include <dcos/internal/RemoteMessage.hpp>

#include <stdint.h>

namespace dcos::internal {

/// Performs @p service on the remote object @p id with @p argument: the
/// reply's value, or its status, or the remote agent's error.
using RemoteForwarder = Result<uint32_t> (*)(RemoteService service, ObjectId id, uint32_t argument);

/// Set by the remote agent when it starts; null until then.
void setRemoteForwarder(RemoteForwarder forwarder);

/// Sends @p message at @p priority to another node's port: its status.
using RemotePortSender = Status (*)(ObjectId port, const Message& message, int priority);

/// Set by the remote agent when it starts; null until then.
void setRemotePortSender(RemotePortSender sender);

/// MessagePortAgent::Send to another node's port, or Status::Remote when no
/// remote agent runs. Out of line: only Send's miss path calls it.
[[gnu::noinline]] Status forwardRemotePortSend(ObjectId port, const Message& message, int priority);

/// Send's status after its local attempt: @p local unless it is Remote, in
/// which case the message goes to the other node's port.
[[gnu::always_inline]] inline Status orRemotePortSend(Status local, ObjectId port, const Message& message,
                                                      int priority)
{
    if (local != Status::Remote) [[likely]] {
        return local;
    }
    return forwardRemotePortSend(port, message, priority);
}

/// Sets an alarm of another node's timer, for the calling task, its owner.
using RemoteAlarmSetter = Status (*)(ObjectId timer, RemoteAlarmKind kind, const AlarmNotification& notification,
                                     uint64_t timeNs);

/// Set by the remote agent when it starts; null until then.
void setRemoteAlarmSetter(RemoteAlarmSetter setter);

/// Sets the alarm on the timer's node (the interval, period or time of day
/// in @p timeNs), or Status::Remote when no remote agent runs. Out of line:
/// only a Set...Alarm's miss path calls it.
[[gnu::noinline]] Status forwardRemoteAlarm(ObjectId timer, RemoteAlarmKind kind,
                                            const AlarmNotification& notification, uint64_t timeNs);

/// A Set...Alarm's status after its local attempt: @p local unless it is
/// Remote, in which case the alarm is set on the timer's node.
[[gnu::always_inline]] inline Status orRemoteAlarm(Status local, ObjectId timer, RemoteAlarmKind kind,
                                                   const AlarmNotification& notification, uint64_t timeNs)
{
    if (local != Status::Remote) [[likely]] {
        return local;
    }
    return forwardRemoteAlarm(timer, kind, notification, timeNs);
}

/// Tells @p owner, a task of another node, that @p timer's alarm went off:
/// queued for the remote agent's notifier, from the tick's interrupt. Set
/// by the remote agent; without one the notification is lost, counted.
using RemoteAlarmQueue = void (*)(ObjectId timer, ObjectId owner, const AlarmNotification& notification);
void setRemoteAlarmQueue(RemoteAlarmQueue queue);
void queueRemoteAlarm(ObjectId timer, ObjectId owner, const AlarmNotification& notification);

/// Asks the other nodes for an object of @p type named @p name.
using RemoteNameResolver = Result<ObjectId> (*)(ObjectType type, const char* name);

/// Set by the remote agent when it starts; null until then.
void setRemoteNameResolver(RemoteNameResolver resolver);

/// Asks the other nodes for an object of @p type named @p name, or NotFound
/// when no remote agent runs. Out of line: only a local miss calls it.
[[gnu::noinline]] Result<ObjectId> remoteNameToObject(ObjectType type, const char* name);

/// NameToObject's answer after the local table's (seed 6.4): @p local
/// unless it is NotFound, in which case a running remote agent asks every
/// node it has a link to for a visible object of that type and name
/// (docs/protocols/remote-transactions.md, "Names").
[[gnu::always_inline]] inline Result<ObjectId> orRemoteName(Result<ObjectId> local, ObjectType type, const char* name)
{
    if (local.status() != Status::NotFound) [[likely]] {
        return local;
    }
    return remoteNameToObject(type, name);
}

/// Allocate of another node's pool or heap (@p service PoolAllocate, or
/// HeapAllocate with the bytes in @p argument): the address the node handed
/// out, as a pointer of this node (the two share memory), or why not;
/// Status::Remote when no remote agent runs. Out of line: only a miss path calls it.
[[gnu::noinline]] Result<void*> forwardRemoteAllocate(RemoteService service, ObjectId id, uint32_t argument);

/// Return of a buffer or segment of another node's pool or heap
/// (@p service PoolReturn or HeapReturn): its status.
[[gnu::noinline]] Status forwardRemoteReturn(RemoteService service, ObjectId id, const void* address);

/// Forwards a request for another node's object, or Status::Remote when no
/// remote agent runs. Out of line: only an agent's miss path calls it.
[[gnu::noinline]] Result<uint32_t> forwardRemote(RemoteService service, ObjectId id, uint32_t argument);

/// A service's status after its local attempt: @p local unless it is
/// Remote, in which case the request is forwarded and its status returned.
[[gnu::always_inline]] inline Status orRemote(Status local, RemoteService service, ObjectId id, uint32_t argument)
{
    if (local != Status::Remote) [[likely]] {
        return local;
    }
    return forwardRemote(service, id, argument).status();
}

/// A read service's result after its local attempt failed with @p local:
/// that status unless it is Remote, else the remote reply's value as T.
template <typename T>
Result<T> remoteValueOr(Status local, RemoteService service, ObjectId id)
{
    if (local != Status::Remote) {
        return local;
    }
    const Result<uint32_t> reply = forwardRemote(service, id, 0);
    if (!reply.ok()) {
        return reply.status();
    }
    if constexpr (__is_same(T, ObjectId)) { // The compiler's trait: the firmware has no <type_traits>.
        return ObjectId::fromRaw(reply.value());
    } else {
        return static_cast<T>(reply.value());
    }
}

} // namespace dcos::internal
