// The message port agent's application interface (seed 7.9).
//
// A port is an N-to-1 mailbox: any task, on any node, and any interrupt
// handler may Send to it, and only the task that owns it receives. Messages
// have a fixed length of sixteen bytes, so sending and receiving cost the
// same whatever is queued. A port is ordered either by priority (32 levels,
// 0 the most urgent, first in first out within a level) or purely first in
// first out; on either kind a negative priority queues the message last in
// first out at its level, in front of the messages already there.
//
// Messages wait in buffers of a kernel message-buffer area shared by all
// ports. AddMsgBufs activates more of the area's static reserve. Send never
// blocks: when no buffer is free it fails with Status::NoMemory and the
// message is not queued, so nothing is dropped without the sender knowing.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// Bytes of user data a message carries (seed 7.9: sixteen).
constexpr size_t kMessageSize = 16;

/// One message: sixteen bytes whose meaning the sender and receiver agree on.
struct Message {
    uint8_t bytes[kMessageSize];
};

static_assert(sizeof(Message) == kMessageSize, "a message is exactly sixteen bytes");

/// How a port orders the messages it queues.
enum class PortOrder : uint8_t {
    Priority, ///< 32 levels, most urgent first; the seed's default.
    Fifo,     ///< First in first out; a non-negative priority has no effect.
};

/// The most urgent message priority (level 0).
constexpr int kMostUrgentMessage = 0;
/// The least urgent message priority (level 31).
constexpr int kLeastUrgentMessage = 31;
/// Queues a message last in first out at level 0, which -0 cannot say.
/// Priorities -1 to -31 mean last in first out at levels 1 to 31.
constexpr int kLifoMostUrgent = -32;

/// The message port agent interface object.
class MessagePortAgent {
public:
    /// Creates a port owned, and received from, by the caller.
    ///
    /// @p name may be null (an unnamed port cannot be found by name) or at
    /// most 15 characters. Fails with InvalidArgument, TableFull (see
    /// AddObjects) or InInterrupt. Cost O(1).
    static Result<ObjectId> Create(const char* name, Visibility visibility, PortOrder order = PortOrder::Priority);

    /// Deletes a port the caller owns (a super user may delete any port).
    ///
    /// A task waiting in Receive is woken with Status::Deleted, and the
    /// messages still queued are discarded, their buffers going back to the
    /// free area. Cost O(1): each of the 32 levels is handed back whole.
    static Status Delete(ObjectId port);

    /// Queues @p message on @p port; never blocks, and is allowed in
    /// interrupt handlers.
    ///
    /// @p priority is 0 (most urgent) to 31, queued first in first out at
    /// that level, or -1 to -31 (and kLifoMostUrgent for level 0), queued
    /// last in first out at that level. A FIFO port ignores the level but
    /// honours the sign. When the owner is waiting in Receive the message is
    /// handed to it directly and takes no buffer. Fails with
    /// InvalidArgument for a priority out of range, NoMemory when no message
    /// buffer is free (the message is then not queued), and the id errors.
    /// Cost O(1).
    static Status Send(ObjectId port, const Message& message, int priority);

    /// Takes the first message of a port the caller owns into @p message.
    ///
    /// With kPoll it fails at once with WouldBlock when the port is empty;
    /// otherwise it waits up to @p timeoutNs nanoseconds (kWaitForever for
    /// no limit) and fails with Timeout, or with Deleted when the port is
    /// deleted meanwhile. Only the owner receives (NotOwner otherwise, even
    /// for a super user), which makes a port N-to-1. Waiting is refused in
    /// an interrupt handler with InInterrupt. Cost O(1).
    static Status Receive(ObjectId port, Message& message, uint64_t timeoutNs);

    /// Activates @p count more message buffers from the static reserve
    /// (privileged configuration service).
    ///
    /// Fails with InvalidArgument for 0, NoMemory when the reserve has fewer
    /// than @p count left (nothing is then activated), NotPermitted for a
    /// task that is not a super user. Cost O(count).
    static Status AddMsgBufs(size_t count);

    /// Finds a port by name among local ports. Fails with NotFound. Cost O(N).
    static Result<ObjectId> NameToObject(const char* name);

    /// Activates @p count more port slots, a multiple of eight (privileged
    /// configuration service). Cost O(count).
    static Status AddObjects(size_t count);

    /// Hands a port the caller owns to another local task (or to the system,
    /// with the null id), which then receives from it and owns it for
    /// resource recovery. Only the owner may give a port away, so no
    /// receiver can be waiting on it meanwhile. Cost O(1).
    static Status XferOwnership(ObjectId port, ObjectId newOwner);
};

inline constexpr MessagePortAgent messagePortAgent{};

} // namespace dcos
