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
    /// Only in replies, to a name query (below): value: the object's id.
    NameToObject = 10,
    /// A request of three frames (port sends, below): the message, its
    /// priority; the reply's value is 0.
    PortSend = 11,
    /// A request of two frames (held acquires, below): Acquire for a task
    /// of the requesting node, which holds a binary semaphore when it gets
    /// it; argument: the time-out, as SemaphoreAcquire's.
    HeldAcquire = 12,
    /// Release by the task that holds a binary semaphore; argument: that
    /// task's id.
    HeldRelease = 13,
    /// A request of three frames (alarms, below): a timer's alarm set by
    /// its owner, a task of the requesting node.
    TimerSetAlarm = 14,
    /// CancelAlarm by the timer's owner; argument: the owner's id.
    TimerCancelAlarm = 15,
    /// BufferPoolAgent::Allocate; argument: 0; value: the buffer's address.
    /// Only between nodes that share memory (docs/protocols/remote-transactions.md,
    /// "Pools and heaps"): the address is the serving node's memory.
    PoolAllocate = 16,
    /// BufferPoolAgent::Return; argument: the buffer's address.
    PoolReturn = 17,
    /// HeapAgent::Allocate; argument: the bytes asked for; value: the segment's address.
    HeapAllocate = 18,
    /// HeapAgent::Return; argument: the segment's address.
    HeapReturn = 19,
};

/// The last service value assigned.
constexpr uint8_t kLastRemoteService = 19;

/// Whether @p service hands out or takes back memory of the serving node,
/// which only a node that shares that memory can use.
constexpr bool isMemoryService(RemoteService service)
{
    return service == RemoteService::PoolAllocate || service == RemoteService::PoolReturn ||
           service == RemoteService::HeapAllocate || service == RemoteService::HeapReturn;
}

/// The value of a reply NotSupported to SemaphoreAcquire or
/// SemaphoreRelease of a binary semaphore: ask again with HeldAcquire or
/// HeldRelease, which name the task that holds it.
constexpr uint32_t kAskHeld = 1;

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
    UnknownNode,     ///< A node's announcement naming node 0 or the broadcast node 0xFFFF.
};

const char* remoteMessageErrorName(RemoteMessageError error);

void encodeRequest(const RemoteRequest& request, uint8_t (&bytes)[kRemoteMessageBytes]);
void encodeReply(const RemoteReply& reply, uint8_t (&bytes)[kRemoteMessageBytes]);

/// Decodes a request of @p length bytes; None and @p request filled in, or why not.
RemoteMessageError decodeRequest(const uint8_t* bytes, size_t length, RemoteRequest& request);
/// Decodes a reply of @p length bytes; None and @p reply filled in, or why not.
RemoteMessageError decodeReply(const uint8_t* bytes, size_t length, RemoteReply& reply);

/// A node's announcement that it started, its first message on a bus since
/// then (docs/protocols/remote-transactions.md, "A node that starts
/// again"): message type NodeStarted, to the broadcast address, bytes 0-1
/// the node's logical id big-endian, bytes 2-7 zero.
struct NodeStarted {
    uint16_t node = 0;
};

void encodeNodeStarted(const NodeStarted& announcement, uint8_t (&bytes)[kRemoteMessageBytes]);
/// Decodes an announcement of @p length bytes; None and @p announcement
/// filled in, or why not: WrongLength, ReservedBits for a byte 2-7 that is
/// not zero, UnknownNode for node 0 or 0xFFFF.
RemoteMessageError decodeNodeStarted(const uint8_t* bytes, size_t length, NodeStarted& announcement);

/// Whether @p value is a status some node may send (every Status value).
bool isStatusValue(uint8_t value);

// ---- port sends ----------------------------------------------------------
//
// MessagePortAgent::Send to another node's port carries a 16-byte message:
// a request of three frames (message type 0x11, to the port's node), sent
// in a row at the requester's priority, so they arrive in order:
//
//     part 0   a request (the layout above), service PortSend: byte 4 the
//              message priority (signed: -32 to 31), bytes 5-7 message
//              bytes 0-2; 8 bytes
//     part 1   byte 0 0x80 | 1 << 4 | the transaction's low four bits,
//              bytes 1-7 message bytes 3-9; 8 bytes
//     part 2   byte 0 0x80 | 2 << 4 | the transaction's low four bits,
//              bytes 1-6 message bytes 10-15; 7 bytes
//
// Byte 0's bit 7, never set in a service, marks a continuation. A requester
// has at most one transaction in flight per value of the low four bits (in
// DCOS they are its call slot), so with its source address they name the
// request a continuation belongs to. The reply is an ordinary reply; a
// retransmission sends all three parts again, with the same transaction.

/// Frames of one port send, and the message bytes each carries.
constexpr size_t kPortSendFrames = 3;
/// Frames of one held acquire.
constexpr size_t kHeldAcquireFrames = 2;
/// Frames of one alarm: a port send's layout (below).
constexpr size_t kAlarmFrames = kPortSendFrames;
constexpr size_t kPortMessageBytes = 16;

/// A port send, whole.
struct PortSendRequest {
    uint8_t transaction = 0;
    uint16_t object = 0;      ///< The port id's low 16 bits.
    int8_t priority = 0;      ///< MessagePortAgent::Send's priority.
    uint8_t message[kPortMessageBytes]{};
};

/// A held acquire, whole (docs/protocols/remote-transactions.md, "Binary
/// semaphores"):
///
///     part 0   a request (the layout above), service HeldAcquire: bytes
///              4-7 the time-out in milliseconds, as SemaphoreAcquire's
///     part 3   byte 0 0x80 | 3 << 4 | the transaction's low four bits,
///              bytes 1-4 the holding task's id (big-endian), bytes 5-7
///              zero; 8 bytes
///
/// Its continuation is numbered 3, a number no port send uses, so a
/// continuation says alone what it belongs to.
struct HeldAcquireRequest {
    uint8_t transaction = 0;
    uint16_t object = 0;      ///< The semaphore id's low 16 bits.
    uint32_t timeoutMs = 0;
    uint32_t holder = 0;      ///< The requesting task's id, whole.
};

/// One continuation frame (part 1 or 2), decoded.
struct Continuation {
    uint8_t part = 0;         ///< 1 or 2 (a port send), 3 (a held acquire).
    uint8_t slot = 0;         ///< The transaction's low four bits.
    uint8_t bytes[7]{};
    uint8_t count = 0;        ///< Message bytes it carries: 7, or 6 in part 2.
};

/// Whether a request frame is a continuation (byte 0's bit 7).
constexpr bool isContinuation(const uint8_t* bytes, size_t length) { return length > 0 && (bytes[0] & 0x80) != 0; }

/// The three frames of @p request and their lengths (8, 8, 7).
void encodePortSend(const PortSendRequest& request, uint8_t (&frames)[kPortSendFrames][kRemoteMessageBytes],
                    uint8_t (&lengths)[kPortSendFrames]);

/// A timer's alarm set by its owner on another node
/// (docs/protocols/remote-transactions.md, "Timers"): three frames laid
/// out as a port send's, service TimerSetAlarm, whose byte 4 is the flags
/// and whose sixteen message bytes are the record:
///
///     flags    bits 1-0 the alarm: 1 watch-dog, 2 day clock, 3 periodic;
///              bit 4 the notification: 0 event, 1 signal; others zero
///     record   bytes 0-3   the owner, the task that sets it (big-endian)
///              bytes 4-7   the notification's event set or signal number
///              bytes 8-15  the time: the interval or period in ns, or the
///                          day clock's time of day in ns since 1970
enum class RemoteAlarmKind : uint8_t { WatchDog = 1, DayClock = 2, Periodic = 3 };

struct AlarmRequest {
    uint8_t transaction = 0;
    uint16_t object = 0;      ///< The timer id's low 16 bits.
    RemoteAlarmKind kind = RemoteAlarmKind::WatchDog;
    bool signal = false;      ///< The notification: a signal, else events.
    uint32_t value = 0;       ///< The events, or the signal number.
    uint32_t owner = 0;       ///< The owner's id, whole.
    uint64_t timeNs = 0;
};

/// An alarm's @p flags and sixteen-byte @p record (the layout above) into
/// @p out's fields but its transaction and object; false when the flags
/// are not defined.
bool decodeAlarmRecord(uint8_t flags, const uint8_t (&record)[kPortMessageBytes], AlarmRequest& out);

/// The three frames of @p request and their lengths (8, 8, 7).
void encodeAlarm(const AlarmRequest& request, uint8_t (&frames)[kAlarmFrames][kRemoteMessageBytes],
                 uint8_t (&lengths)[kAlarmFrames]);

/// The two frames of @p request.
void encodeHeldAcquire(const HeldAcquireRequest& request,
                       uint8_t (&frames)[kHeldAcquireFrames][kRemoteMessageBytes]);

/// Decodes a continuation of @p length bytes: None, WrongLength (part 1 or
/// 3 not 8 bytes, part 2 not 7), UnknownService (part number 0, or bit 6
/// set) or ReservedBits (part 3 whose bytes 5-7 are not zero).
RemoteMessageError decodeContinuation(const uint8_t* bytes, size_t length, Continuation& part);

/// Puts one requester's request of several frames back together: part 0
/// (a decoded request of service PortSend or HeldAcquire), then its
/// continuations in order.
class ContinuedRequestAssembler {
public:
    enum class Outcome : uint8_t {
        Started,   ///< Part 0 taken.
        Taken,     ///< A continuation in turn, not the last.
        Complete,  ///< The last part: the request is whole.
        Dropped,   ///< Out of turn, of another transaction or malformed: what was gathered is dropped.
    };

    /// Part 0 (PortSend, TimerSetAlarm or HeldAcquire); Dropped for a
    /// service of one frame.
    Outcome start(const RemoteRequest& first);
    Outcome take(const Continuation& part);
    /// The service of the request gathered.
    RemoteService service() const { return first_.service; }
    /// The request, once Complete, as what its service is.
    PortSendRequest portSend() const;
    HeldAcquireRequest heldAcquire() const;
    /// An alarm; false when its flags are not defined (ReservedBits).
    bool alarm(AlarmRequest& out) const;

private:
    uint8_t next_ = 0;        // The part expected; 0 when none.
    RemoteRequest first_{};
    uint8_t bytes_[kPortMessageBytes]{}; // The continuations' bytes, in order.
};

// ---- routed requests -------------------------------------------------------
//
// A request for a node that is reached through a gateway (its network
// address lies behind a route, NetworkInterfacesManager.hpp) goes to the
// gateway as message type 0x13, RoutedRequest: a route header, then the
// request's own frames exactly as above (one frame, a held acquire's
// two or a port send's three), in a row at the requester's priority:
//
//     header   byte 0   0xC0 | hops left (1 to kRouteHops)
//              byte 1   the transaction number, as in the request
//              bytes 2-3 the destination's logical node
//
// Byte 0's bits 7-6 both set mark a header: a service never has bit 7, a
// continuation has bits 7-6 = 10. The gateway performs the request as its
// own remote transaction to that node, on a worker at the requester's
// priority, and replies with what it got: a request crosses one hop at a
// time, each with its own watchdog and duplicate filter. A gateway that
// must forward through another gateway sends a header with one hop fewer;
// a request with no hop left is answered Unreachable, so a loop in the
// routes costs a few transactions, never a circle without end. A request
// frame of type 0x13 whose header did not arrive is dropped: without its
// destination, it would name an object of the gateway.

/// How many times a request may go as a routed request: from its requester
/// to the first gateway, and from each gateway that must pass it to another.
constexpr uint8_t kRouteHops = 4;
/// Bytes of a route header.
constexpr size_t kRouteHeaderBytes = 4;

struct RouteHeader {
    uint8_t hopsLeft = kRouteHops;
    uint8_t transaction = 0;
    uint16_t destination = 0;
};

/// Whether a routed request frame is a route header (byte 0's bits 7-6).
constexpr bool isRouteHeader(const uint8_t* bytes, size_t length)
{
    return length > 0 && (bytes[0] & 0xC0) == 0xC0;
}

void encodeRouteHeader(const RouteHeader& header, uint8_t (&bytes)[kRouteHeaderBytes]);
/// Decodes a header of @p length bytes: None, WrongLength (not
/// kRouteHeaderBytes), ReservedBits (not a header, bits 5-4 set, or hops
/// left 0 or above kRouteHops).
RemoteMessageError decodeRouteHeader(const uint8_t* bytes, size_t length, RouteHeader& header);

// ---- name queries --------------------------------------------------------
//
// NameToObject asked of every node (message type 0x12, to the broadcast
// address): three frames of eight bytes, each
//
//     byte 0   bits 7-6 part (0, 1, 2), bits 5-4 zero, bits 3-0 the object type
//     byte 1   transaction number, as in a request
//     part 0   bytes 2-7 name bytes 0-5
//     part 1   bytes 2-7 name bytes 6-11
//     part 2   bytes 2-5 name bytes 12-15, byte 6 relays left (0 to
//              kNameRelays), byte 7 zero
//
// Byte 6 of part 2 matters only in a query sent to one node, a gateway,
// alone (a relayed query): how many further gateways that gateway may pass
// the query on to (docs/protocols/remote-transactions.md, "Gateways"). A
// broadcast query carries 0.
//
// The name is NUL-padded to 16 bytes: 1 to 15 characters and at least one
// NUL. A node that has an object of that type and name visible to the
// asker answers with a RemoteReply (service NameToObject, the transaction,
// the id as its value); a node that has none says nothing.

/// Frames of one name query, and the bytes of the name field.
constexpr size_t kNameQueryFrames = 3;
constexpr size_t kNameQueryNameBytes = 16;
/// The most relays a relayed name query may have left: with the first
/// gateway's own, a name is found up to kRouteHops gateways away, as far as
/// a routed request reaches.
constexpr uint8_t kNameRelays = kRouteHops - 1;

struct NameQueryPart {
    uint8_t part = 0;        ///< 0, 1 or 2.
    uint8_t type = 0;        ///< The ObjectType's value.
    uint8_t transaction = 0;
    uint8_t bytes[6]{};      ///< The name bytes it carries (4 in part 2).
    uint8_t relays = 0;      ///< Part 2's relays left, 0 to kNameRelays (0 in parts 0 and 1).
};

enum class NameQueryError : uint8_t {
    None,
    WrongLength,   ///< Not eight bytes.
    ReservedBits,  ///< A part number 3, bits 5-4 set, part 2's byte 7 not zero or its byte 6 above kNameRelays.
    BadType,       ///< A type whose objects have no names (see isNamedObjectType).
};

/// Whether objects of type @p type have names: tasks, timers, devices,
/// buffer pools, heaps, message ports, publishers and semaphores.
bool isNamedObjectType(uint8_t type);

const char* nameQueryErrorName(NameQueryError error);

/// The three frames asking for the object of @p type named @p name (1 to
/// 15 characters; longer names are cut, which no table holds anyway), with
/// @p relays left for a relayed query (held to kNameRelays).
void encodeNameQuery(uint8_t type, uint8_t transaction, const char* name,
                     uint8_t (&frames)[kNameQueryFrames][kRemoteMessageBytes], uint8_t relays = 0);

/// Decodes one frame of @p length bytes; None and @p part filled in, or why not.
NameQueryError decodeNameQueryPart(const uint8_t* bytes, size_t length, NameQueryPart& part);

/// Puts one sender's name query back together; parts come in order on a bus.
class NameQueryAssembler {
public:
    /// Takes a part; true when it completed a query whose name is well formed
    /// (1 to 15 characters, NUL-padded): type(), transaction(), name().
    bool take(const NameQueryPart& part);

    uint8_t type() const { return type_; }
    uint8_t transaction() const { return transaction_; }
    /// The relays left that part 2 carried.
    uint8_t relays() const { return relays_; }
    /// The name, NUL-terminated.
    const char* name() const { return name_; }

private:
    uint8_t next_ = 0;
    uint8_t type_ = 0;
    uint8_t transaction_ = 0;
    uint8_t relays_ = 0;
    char name_[kNameQueryNameBytes]{};
};

} // namespace dcos::internal
