// The system messages of remote transactions (seed 6.4, Fig. 6.3): what a
// node's system agents send each other when a primitive names an object of
// another node. docs/protocols/remote-transactions.md is the specification;
// this is its only encoder and decoder, pure code shared by the kernel, the
// host tests and the fuzz target.
//
// Every message is exactly eight bytes, one classic CAN frame's data field,
// so a fixed-size primitive costs one request frame and one reply frame.
// Multi-byte fields are big-endian (network byte order) whatever the host,
// so a node of another architecture, or a bus analyser, reads them alike.
//
//     request   0 service | 1 transaction | 2-3 object (type, index) | 4-7 argument
//     reply     0 service | 1 transaction | 2 status | 3 flags | 4-7 value
//
// The object field is the id's low 16 bits: a request goes to the node that
// holds the object, which puts its own node number back in front. The
// transaction number lets the requester match a reply to its request and
// the server recognise a request it has seen (a retransmission) so that no
// request is executed twice.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// Bytes of every remote transaction message.
constexpr size_t kRemoteMessageBytes = 8;

/// The primitives a remote transaction carries. Values never change once
/// assigned; 0 is never a service.
enum class RemoteService : uint8_t {
    SemaphoreAcquire = 1,  ///< argument: the time-out in milliseconds (kRemotePoll, kRemoteForever).
    SemaphoreRelease = 2,  ///< argument: 0.
    SemaphoreGetCount = 3, ///< argument: 0; value: the count.
    PostEvent = 4,         ///< argument: the events.
    SendSignal = 5,        ///< argument: the signal number.
    TaskGetState = 6,      ///< argument: 0; value: the TaskState.
    TaskGetPriority = 7,   ///< argument: 0; value: the static priority.
    SemaphoreGetHolder = 8, ///< argument: 0; value: the holding task's id (0: free).
    /// argument: 0; value: the publisher's data identifier. The publisher
    /// sends its latest page again (docs/protocols/publications.md).
    DsmOpen = 9,
};

/// The last service value assigned.
constexpr uint8_t kLastRemoteService = 9;

/// A short name of a service, for the console and logs.
const char* remoteServiceName(RemoteService service);

/// The time-out argument of SemaphoreAcquire: do not wait.
constexpr uint32_t kRemotePoll = 0;
/// The time-out argument of SemaphoreAcquire: wait without a limit.
constexpr uint32_t kRemoteForever = 0xFFFFFFFF;

/// A time-out in nanoseconds (kPoll, kWaitForever or a span) as the
/// milliseconds of a request: rounded up, so a wait is never cut short, and
/// held below kRemoteForever.
uint32_t remoteTimeoutMs(uint64_t timeoutNs);
/// The other way: the nanoseconds the serving node waits.
uint64_t remoteTimeoutNs(uint32_t timeoutMs);

struct RemoteRequest {
    RemoteService service = RemoteService::SemaphoreAcquire;
    uint8_t transaction = 0;
    /// The object's type and index, the id's low 16 bits.
    uint16_t object = 0;
    uint32_t argument = 0;

    /// The object's id on node @p node.
    ObjectId objectOn(uint16_t node) const { return ObjectId::fromRaw((uint32_t{node} << 16) | object); }
};

/// Reply flags (byte 3).
constexpr uint8_t kReplyPending = 0x01; ///< The request is queued or running; the final reply follows.
constexpr uint8_t kReplyFlagsDefined = kReplyPending;

struct RemoteReply {
    RemoteService service = RemoteService::SemaphoreAcquire;
    uint8_t transaction = 0;
    Status status = Status::Ok;
    /// True for a keep-alive: the request is known and not finished.
    bool pending = false;
    uint32_t value = 0;
};

/// Why a message was refused; each is counted by the receiver.
enum class RemoteMessageError : uint8_t {
    None,
    WrongLength,     ///< Not exactly kRemoteMessageBytes.
    UnknownService,  ///< A service value that is not assigned.
    NullObject,      ///< A request for object 0 (no type, no index).
    UnknownStatus,   ///< A reply's status that no node sends.
    ReservedBits,    ///< A reply flag that is not defined.
};

const char* remoteMessageErrorName(RemoteMessageError error);

void encodeRequest(const RemoteRequest& request, uint8_t (&bytes)[kRemoteMessageBytes]);
void encodeReply(const RemoteReply& reply, uint8_t (&bytes)[kRemoteMessageBytes]);

/// Decodes a request of @p length bytes; None and @p request filled in, or why not.
RemoteMessageError decodeRequest(const uint8_t* bytes, size_t length, RemoteRequest& request);
/// Decodes a reply of @p length bytes; None and @p reply filled in, or why not.
RemoteMessageError decodeReply(const uint8_t* bytes, size_t length, RemoteReply& reply);

/// Whether @p value is a status some node may send (every Status value).
bool isStatusValue(uint8_t value);

} // namespace dcos::internal
