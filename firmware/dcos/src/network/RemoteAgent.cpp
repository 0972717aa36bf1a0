// The remote agent (RemoteAgent.hpp; seed 6.4, Fig. 6.3): remote
// transactions over the links of the network interfaces manager.
#include <dcos/MessagePortAgent.hpp>
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/DsmManager.hpp>
#include <dcos/internal/GlobalTimeService.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/NameService.hpp>
#include <dcos/internal/NetworkTables.hpp>
#include <dcos/internal/PublicationMessage.hpp>
#include <dcos/internal/RemoteAgent.hpp>
#include <dcos/internal/FlashServiceHooks.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/RemoteMemoryHolds.hpp>
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/HeapManager.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/SemaphoreManager.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimerManager.hpp>
#include <dcos/GregorianCalendar.hpp>
#include <dcos/internal/WaitQueue.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/InstructionCounter.hpp>

namespace dcos {

namespace internal {

namespace {

using Lock = arch_x86::InterruptGuard;

constexpr uint64_t kWatchdogNs = uint64_t{kRemoteWatchdogMs} * 1'000'000;
constexpr uint8_t kSlotBits = 4;
constexpr uint8_t kSlotMask = (1u << kSlotBits) - 1;
constexpr size_t kTaskStackBytes = 4096;

// ---- the links ------------------------------------------------------------

// The link of each interface, null while it has none. A link knows its own
// physical address (Start), and puts it in every frame it sends.
NetworkLink* links[kNetworkInterfaces];

// The interface's event for the receiver task: bit n for interface n.
constexpr uint32_t eventOf(uint8_t interface) { return 1u << interface; }
// The receiver's event for publications written by interrupt handlers.
constexpr uint32_t kDeferredPublicationsEvent = 1u << 31;
static_assert(kNetworkInterfaces <= 31);
static_assert(kNameQueryNameBytes == kPortMessageBytes && kPortMessageBytes == kMessageSize,
              "a served entry's payload holds a name or a port message");

// ---- instruction counts (RemoteInstructions) --------------------------------

// The instruction counter (arch_x86/InstructionCounter.hpp), 0 in an image
// without one. Out of line, like the records below: a transaction pays a
// call per read, and the agent's code keeps the counting image's
// bookkeeping in one place rather than in every caller's path.
[[gnu::noinline]] uint64_t readCounter() { return arch_x86::instructionCount(); }

// The instructions since @p start, a stamp or a read; 0 when it is 0.
[[gnu::noinline]] uint32_t instructionsSince(uint64_t start)
{
    return start == 0 ? 0 : static_cast<uint32_t>(readCounter() - start);
}

// ---- the requesting side ----------------------------------------------------

struct CallSlot {
    WaitQueue waiter; // The caller, while it waits for a word from the peer.
    ObjectId caller;  // Null while the slot is free.
    uint8_t generation = 0;
    uint8_t transaction = 0;
    uint8_t interface = 0;
    uint32_t peer = 0;
    RemoteService service = RemoteService::SemaphoreAcquire;
    bool done = false;    // The final reply came: status and value hold it.
    bool heard = false;   // A pending reply came in this watchdog period.
    Status status = Status::Ok;
    uint32_t value = 0;
    // The instruction counter at the transaction's start and once its
    // request was on the link, and the final reply's stamp
    // (SystemMessage::instructionStamp): RemoteInstructions' caller side.
    uint64_t begun = 0;
    uint64_t queued = 0;
    uint64_t replyStamp = 0;
    // A node behind a gateway: the request goes to the gateway (peer)
    // behind a route header naming the node, with hops hops left.
    bool routed = false;
    uint16_t destination = 0;
    uint8_t hops = 0;
};

CallSlot calls[kRemoteCalls];

// ---- the serving side -------------------------------------------------------

enum class ServedState : uint8_t { Free, Queued, Running, Done };

struct ServedEntry {
    ServedState state = ServedState::Free;
    uint8_t interface = 0;
    uint8_t priority = 0;
    uint32_t source = 0;
    RemoteRequest request{};
    uint32_t order = 0; // Arrival order while queued; completion order once done.
    uint64_t heardNs = 0; // Uptime when the request last arrived, retransmissions included.
    bool superseded = false; // Its requester has begun another transaction on the same call slot.
    bool silent = false;     // Done, and nothing to answer: a name query this node has no object for.
    // The instruction stamp of the request's last frame, and what its
    // earlier frames cost (RemoteInstructions::servePartsBefore).
    uint64_t arrivalStamp = 0;
    uint32_t partsBefore = 0;
    // The node whose object the request names: this node, or for a routed
    // request the destination of its route header, and the hops it has left.
    uint16_t node = 0;
    uint8_t hopsLeft = 0;
    // A name query sent to this node alone, as a gateway: what it does not
    // have, it asks the buses beyond (docs/protocols/remote-transactions.md,
    // "Gateways"). A requester sends such a query with the same transaction
    // as its broadcast one, so the two are told apart by this flag.
    bool relay = false;
    // A name query's name, NUL-padded (service NameToObject, the type in
    // request.object), or a port send's message (service PortSend).
    uint8_t payload[kPortMessageBytes]{};
    uint8_t reply[kRemoteMessageBytes]{};
};

// A requester that waits retransmits its request every watchdog period, so
// one not heard for as long as it would itself wait before giving up has
// given up, or died: the serving node stops waiting for it.
constexpr uint64_t kRequesterSilenceNs = kWatchdogNs * kRemoteSilentPeriods;

// How long a finished entry's reply answers retransmissions after the last
// one was heard. A requester whose reply was lost sends its request again
// every watchdog period, and gives up when it has heard nothing for
// kRequesterSilenceNs; twice that is past any retransmission it can still
// send. A request with the entry's number that comes later is a new one.
constexpr uint64_t kServedReplyLifetimeNs = 2 * kRequesterSilenceNs;

ServedEntry served[kRemoteServed];
uint32_t arrivals = 0;
uint32_t completions = 0;
WaitQueue idleWorkers;
// Each worker's task and the entry it runs (null when idle), so that a
// worker that forwards a routed request through another gateway passes on
// one hop fewer (routedHopsLeft).
ObjectId workerIds[kRemoteWorkers];
ServedEntry* workerJobs[kRemoteWorkers];

RemoteStatistics statistics;
bool started = false;
ObjectId receiverTask;

// ---- sending ------------------------------------------------------------------

// Sends @p data as a message of @p type over @p interface's link; false
// when the interface has no link or its queue is full. Task context.
bool sendBytes(uint8_t interface, SystemMessageType type, uint8_t priority, uint32_t destination,
               const uint8_t* data, uint8_t length)
{
    SystemMessage message;
    message.priority = priority;
    message.type = type;
    message.destination = destination;
    message.length = length;
    __builtin_memcpy(message.data, data, length);
    return sendOnLink(interface, message);
}

bool sendMessage(uint8_t interface, SystemMessageType type, uint8_t priority, uint32_t destination,
                 const uint8_t (&data)[kRemoteMessageBytes])
{
    return sendBytes(interface, type, priority, destination, data, kRemoteMessageBytes);
}

// Whether @p interface joins nodes of one controller (seed 6.4's regional
// scope): the dual-Pentium board's shared-memory link, not a fieldbus.
bool withinController(uint8_t interface)
{
    const Result<NetworkInterface> entry = NetworkInterfacesManager::GetInterface(interface);
    return entry.ok() && entry.value().kind == InterfaceKind::SharedMemory;
}

// Whether a publisher of @p visibility is published over @p interface.
bool reaches(Visibility visibility, uint8_t interface)
{
    if (visibility == Visibility::Global) {
        return true;
    }
    return visibility == Visibility::Regional && withinController(interface);
}

void sendReply(uint8_t interface, uint8_t priority, uint32_t destination, const RemoteReply& reply)
{
    uint8_t data[kRemoteMessageBytes];
    encodeReply(reply, data);
    (void)sendMessage(interface, SystemMessageType::RemoteReply, priority, destination, data);
}

// ---- the requesting side: forward -------------------------------------------

// A free call slot, or null. Slots whose caller has died (killed while it
// waited) are taken back here: the search is O(kRemoteCalls) and only a
// request pays it. Under the lock.
CallSlot* takeCallSlot(Task& self)
{
    for (size_t i = 0; i < kRemoteCalls; ++i) {
        CallSlot& slot = calls[i];
        const bool free = slot.caller.isNull() ||
                          (slot.waiter.isEmpty() && !TaskManager::resolve(slot.caller).ok());
        if (free) {
            slot.caller = self.id;
            slot.generation = static_cast<uint8_t>((slot.generation + 1) & kSlotMask);
            slot.transaction = static_cast<uint8_t>((slot.generation << kSlotBits) | i);
            slot.done = false;
            slot.heard = false;
            return &slot;
        }
    }
    return nullptr;
}

// A call slot for @p self's transaction of @p service with @p peer on
// @p interface, counted as a request; null (counted) when every slot is
// in use. Under the lock.
CallSlot* openCall(Task& self, RemoteService service, uint8_t interface, uint32_t peer)
{
    CallSlot* const slot = takeCallSlot(self);
    if (slot == nullptr) {
        ++statistics.noCallSlot;
        return nullptr;
    }
    slot->interface = interface;
    slot->peer = peer;
    slot->service = service;
    ++statistics.requests;
    return slot;
}

// The caller's side once its call slot is taken: sends the request with
// @p send, again after every silent watchdog period, and blocks until the
// final reply (its status and value) or kRemoteSilentPeriods silent
// periods in a row (Unreachable). @p begun is the instruction counter at
// the transaction's start (0 without a counter).
template <typename Send>
Result<uint32_t> awaitReply(CallSlot& slot, uint64_t begun, Send send, uint32_t* errorValue = nullptr);

// The hops left of the routed request @p self serves, when it is a worker
// serving one (so it forwards the request on); 0 otherwise. Under the lock.
uint8_t routedHopsLeft(const Task& self)
{
    for (size_t i = 0; i < kRemoteWorkers; ++i) {
        if (workerIds[i] == self.id && workerJobs[i] != nullptr) {
            return workerJobs[i]->node != localNode() ? workerJobs[i]->hopsLeft : 0;
        }
    }
    return 0;
}

// The call slot of @p self's transaction of @p service on the object @p id
// of another node: the node resolved to an interface and a physical
// address, and a slot taken; or why not.
Result<CallSlot*> openRemoteCall(Task& self, RemoteService service, ObjectId id)
{
    if (inInterruptContext()) {
        return Status::InInterrupt; // A remote transaction blocks its caller.
    }
    if (Scheduler::dispatchHeld()) {
        // Nor can a task that holds dispatch block: blockOn would return at
        // once and leave it linked in the slot's wait queue, where the next
        // reply on that slot would wake it instead of that call's caller.
        return Status::Deadlock;
    }
    const Result<NextHop> hop = NetworkInterfacesManager::Resolve(id.node());
    if (!hop.ok()) {
        // A node the tables do not know stays "remote object unreachable",
        // as before there were tables; a known node with no way to it is
        // Unreachable.
        return hop.status() == Status::NotFound ? Status::Remote : Status::Unreachable;
    }
    // A node behind a gateway is asked through it: the request goes to the
    // gateway behind a route header that names the node (RemoteMessage.hpp,
    // routed requests).
    const bool routed = hop.value().via.raw() != hop.value().destination.raw();
    const uint8_t interface = hop.value().interface;
    if (isMemoryService(service) && (routed || !withinController(interface))) {
        // A buffer or segment is memory of its node (seed 7.7, 7.8): only a
        // node that shares that memory, over the board's own link, can use
        // its address. Refused here, before anything is sent.
        return Status::NotSupported;
    }
    Lock lock;
    if (links[interface] == nullptr) {
        return Status::Unreachable;
    }
    uint8_t hops = kRouteHops;
    if (routed) {
        const uint8_t left = routedHopsLeft(self);
        if (left == 1) {
            return Status::Unreachable; // No hop left for another gateway: a loop in the routes.
        }
        hops = left == 0 ? kRouteHops : static_cast<uint8_t>(left - 1);
    }
    CallSlot* const slot = openCall(self, service, interface, hop.value().physical);
    if (slot == nullptr) {
        return Status::Busy;
    }
    slot->routed = routed;
    slot->destination = id.node();
    slot->hops = hops;
    statistics.routedRequests += routed ? 1 : 0;
    return slot;
}

// Sends the @p count frames of @p slot's request to its peer at @p priority:
// behind a route header, as routed requests, for a node behind a gateway.
// Stops at a frame the link did not take: the peer drops the incomplete
// request, and the watchdog sends all of it again.
bool sendRequest(const CallSlot& slot, uint8_t priority, const uint8_t (*frames)[kRemoteMessageBytes],
                 const uint8_t* lengths, size_t count)
{
    SystemMessageType type = SystemMessageType::RemoteRequest;
    if (slot.routed) {
        RouteHeader header;
        header.hopsLeft = slot.hops;
        header.transaction = slot.transaction;
        header.destination = slot.destination;
        uint8_t bytes[kRouteHeaderBytes];
        encodeRouteHeader(header, bytes);
        if (!sendBytes(slot.interface, SystemMessageType::RoutedRequest, priority, slot.peer, bytes,
                       kRouteHeaderBytes)) {
            return false;
        }
        type = SystemMessageType::RoutedRequest;
    }
    for (size_t i = 0; i < count; ++i) {
        if (!sendBytes(slot.interface, type, priority, slot.peer, frames[i], lengths[i])) {
            return false;
        }
    }
    return true;
}

// The most frames one request takes (a port send's, an alarm's).
constexpr size_t kMostRequestFrames = kPortSendFrames;
static_assert(kAlarmFrames <= kMostRequestFrames && kHeldAcquireFrames <= kMostRequestFrames);

// One transaction of @p service on another node's @p id: a call slot, then
// the request that @p encode lays out for the slot's transaction number
// (it fills the frames and their lengths, and says how many), sent again
// after every silent watchdog period, at the caller's running priority, so
// a task that inherited urgency asks with it; the reply's status and
// value, a refusal's value in @p errorValue.
template <typename Encode>
Result<uint32_t> transact(RemoteService service, ObjectId id, Encode encode, uint32_t* errorValue = nullptr)
{
    // The transaction's instructions count from here (RemoteInstructions).
    const uint64_t begun = readCounter();
    Task& self = Scheduler::current();
    const Result<CallSlot*> opened = openRemoteCall(self, service, id);
    if (!opened.ok()) {
        return opened.status();
    }
    CallSlot* const slot = opened.value();
    uint8_t frames[kMostRequestFrames][kRemoteMessageBytes];
    uint8_t lengths[kMostRequestFrames];
    const size_t count = encode(slot->transaction, frames, lengths);
    // The parts in a row: a part the link did not take leaves a request the
    // server drops, so the rest is not sent; the watchdog sends all again.
    return awaitReply(
        *slot, begun, [&] { (void)sendRequest(*slot, self.priority, frames, lengths, count); }, errorValue);
}

// One transaction of @p service on @p id with @p argument: one request
// frame, or for HeldAcquire the two frames naming @p holder.
Result<uint32_t> call(RemoteService service, ObjectId id, uint32_t argument, ObjectId holder,
                      uint32_t* errorValue = nullptr)
{
    const uint16_t object = static_cast<uint16_t>(id.raw() & 0xFFFF);
    return transact(
        service, id,
        [&](uint8_t transaction, uint8_t (&frames)[kMostRequestFrames][kRemoteMessageBytes],
            uint8_t (&lengths)[kMostRequestFrames]) -> size_t {
            lengths[0] = lengths[1] = kRemoteMessageBytes;
            if (service == RemoteService::HeldAcquire) {
                HeldAcquireRequest request;
                request.transaction = transaction;
                request.object = object;
                request.timeoutMs = argument;
                request.holder = holder.raw();
                uint8_t held[kHeldAcquireFrames][kRemoteMessageBytes];
                encodeHeldAcquire(request, held);
                __builtin_memcpy(frames, held, sizeof held);
                return kHeldAcquireFrames;
            }
            RemoteRequest request;
            request.service = service;
            request.transaction = transaction;
            request.object = object;
            request.argument = argument;
            encodeRequest(request, frames[0]);
            return 1;
        },
        errorValue);
}

// Ids of other nodes' semaphores that answered kAskHeld: binary ones,
// asked for with the held forms from the first frame on. Round robin.
constexpr size_t kBinaryIdsKnown = 8;
ObjectId binaryIds[kBinaryIdsKnown];
size_t nextBinaryId = 0;

bool knownBinary(ObjectId id)
{
    Lock lock;
    for (const ObjectId known : binaryIds) {
        if (known == id) {
            return true;
        }
    }
    return false;
}

void rememberBinary(ObjectId id)
{
    Lock lock;
    binaryIds[nextBinaryId] = id;
    nextBinaryId = (nextBinaryId + 1) % kBinaryIdsKnown;
}

// Whether @p self is a worker serving a routed request: it passes the
// request on as it came, held forms and refusals included.
bool servingRouted(const Task& self)
{
    Lock lock;
    return routedHopsLeft(self) != 0;
}

// The held form of an Acquire or Release, for the calling task.
Result<uint32_t> callHeld(RemoteService service, ObjectId id, uint32_t argument)
{
    const ObjectId self = Scheduler::current().id;
    return service == RemoteService::SemaphoreAcquire ? call(RemoteService::HeldAcquire, id, argument, self)
                                                      : call(RemoteService::HeldRelease, id, self.raw(), self);
}

// RemoteForward.hpp's forwarder. An Acquire or Release of a binary
// semaphore goes in the held form, which names the calling task: at once
// when the id is known to be binary, else after the plain form's kAskHeld.
Result<uint32_t> forward(RemoteService service, ObjectId id, uint32_t argument)
{
    const bool semaphore = service == RemoteService::SemaphoreAcquire || service == RemoteService::SemaphoreRelease;
    if (semaphore && knownBinary(id) && !servingRouted(Scheduler::current())) {
        return callHeld(service, id, argument);
    }
    uint32_t errorValue = 0;
    const Result<uint32_t> result = call(service, id, argument, ObjectId::null(), &errorValue);
    if (semaphore && result.status() == Status::NotSupported && errorValue == kAskHeld &&
        !servingRouted(Scheduler::current())) {
        rememberBinary(id);
        return callHeld(service, id, argument);
    }
    return result;
}

// MessagePortAgent::Send to another node's port (RemoteForward.hpp's port
// sender): the three frames of a port send, again after every silent
// watchdog period, and the reply's status.
Status forwardPortSend(ObjectId port, const Message& message, int priority)
{
    return transact(RemoteService::PortSend, port,
                    [&](uint8_t transaction, uint8_t (&frames)[kMostRequestFrames][kRemoteMessageBytes],
                        uint8_t (&lengths)[kMostRequestFrames]) -> size_t {
                        PortSendRequest request;
                        request.transaction = transaction;
                        request.object = static_cast<uint16_t>(port.raw() & 0xFFFF);
                        request.priority = static_cast<int8_t>(priority);
                        __builtin_memcpy(request.message, message.bytes, kPortMessageBytes);
                        encodePortSend(request, frames, lengths);
                        return kPortSendFrames;
                    })
        .status();
}

// An alarm of another node's timer, set for @p owner (RemoteForward.hpp's
// alarm setter passes the calling task; a gateway the owner it was asked
// for): the three frames of an alarm, again after every silent watchdog
// period, and the reply's status.
Status callAlarm(ObjectId timer, RemoteAlarmKind kind, const AlarmNotification& notification, uint64_t timeNs,
                 ObjectId owner)
{
    return transact(RemoteService::TimerSetAlarm, timer,
                    [&](uint8_t transaction, uint8_t (&frames)[kMostRequestFrames][kRemoteMessageBytes],
                        uint8_t (&lengths)[kMostRequestFrames]) -> size_t {
                        AlarmRequest request;
                        request.transaction = transaction;
                        request.object = static_cast<uint16_t>(timer.raw() & 0xFFFF);
                        request.kind = kind;
                        request.signal = notification.kind == AlarmNotification::Kind::Signal;
                        request.value = notification.value;
                        request.owner = owner.raw();
                        request.timeNs = timeNs;
                        encodeAlarm(request, frames, lengths);
                        return kAlarmFrames;
                    })
        .status();
}

Status forwardAlarm(ObjectId timer, RemoteAlarmKind kind, const AlarmNotification& notification, uint64_t timeNs)
{
    return callAlarm(timer, kind, notification, timeNs, Scheduler::current().id);
}

// Any interface, any sender: the call slot of a name query, asked of every node.
constexpr uint8_t kAnyInterface = 0xFF;

// How a name query goes beyond the buses it is broadcast on.
struct NameRelay {
    // Sent to each route's gateway too, as a relayed query with @p relays
    // left for the gateway to pass on; not at all when false.
    bool throughGateways = false;
    uint8_t relays = 0;
    // The node that relayed the query to this one (its interface and
    // physical address), which gets no relayed query back.
    uint8_t fromInterface = 0xFF;
    uint32_t fromPhysical = NetworkLink::kBroadcast;
};

// NameToObject asked of other nodes: the query broadcast on every attached
// link but @p except (kAnyInterface: none), and, as @p relay says, sent to
// each route's gateway too, which asks the buses beyond it and, with relays
// left, its own routes' gateways. The first node that has a visible object
// of that type and name answers with its id; when none does, every node
// stays silent, and after the watchdog's silent periods the answer is
// NotFound.
Result<ObjectId> askForName(ObjectType type, const char* name, uint8_t except, const NameRelay& relay)
{
    const uint64_t begun = readCounter();
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (Scheduler::dispatchHeld()) {
        // The query would block its caller, which cannot while it holds
        // dispatch (see openRemoteCall). The application loader holds it
        // while it checks that the names it declares are free, and that
        // check is of this node's tables: a name query then answers from
        // them alone.
        return Status::NotFound;
    }
    Task& self = Scheduler::current();
    CallSlot* slot;
    {
        Lock lock;
        bool anyLink = false;
        for (uint8_t interface = 0; interface < kNetworkInterfaces; ++interface) {
            anyLink = anyLink || (links[interface] != nullptr && interface != except);
        }
        if (!anyLink) {
            return Status::NotFound;
        }
        slot = openCall(self, RemoteService::NameToObject, kAnyInterface, NetworkLink::kBroadcast);
        if (slot == nullptr) {
            return Status::Busy;
        }
    }
    NextHop gateways[NetworkTables::kRoutes];
    const size_t gatewayCount = relay.throughGateways ? gatewayHops(gateways) : 0;
    // The broadcast query, and the one relayed to gateways, which differ
    // in the relays left only.
    uint8_t frames[kNameQueryFrames][kRemoteMessageBytes];
    uint8_t relayedFrames[kNameQueryFrames][kRemoteMessageBytes];
    encodeNameQuery(static_cast<uint8_t>(type), slot->transaction, name, frames);
    encodeNameQuery(static_cast<uint8_t>(type), slot->transaction, name, relayedFrames, relay.relays);
    // The parts in a row, to one destination; false when the link did not take one.
    const auto sendQuery = [&](uint8_t interface, uint32_t destination) {
        const bool relayed = destination != NetworkLink::kBroadcast;
        for (size_t part = 0; part < kNameQueryFrames; ++part) {
            if (!sendMessage(interface, SystemMessageType::NameQuery, self.priority, destination,
                             relayed ? relayedFrames[part] : frames[part])) {
                return false;
            }
        }
        return true;
    };
    const Result<uint32_t> found = awaitReply(*slot, begun, [&] {
        for (uint8_t interface = 0; interface < kNetworkInterfaces; ++interface) {
            if (interface != except) {
                (void)sendQuery(interface, NetworkLink::kBroadcast);
            }
        }
        for (size_t i = 0; i < gatewayCount; ++i) {
            if (gateways[i].interface != relay.fromInterface || gateways[i].physical != relay.fromPhysical) {
                (void)sendQuery(gateways[i].interface, gateways[i].physical);
            }
        }
    });
    if (!found.ok()) {
        return found.status() == Status::Unreachable ? Status::NotFound : found.status();
    }
    const ObjectId id = ObjectId::fromRaw(found.value());
    // Outside input: an id of another type, or of this node, is no answer.
    if (id.type() != type || id.node() == localNode()) {
        return Status::Corrupted;
    }
    return id;
}

// NameToObject asked of every node this node reaches (RemoteForward.hpp's
// resolver): those on its buses, and through its routes' gateways those
// up to kRouteHops gateways beyond, as far as a routed request goes.
Result<ObjectId> forwardName(ObjectType type, const char* name)
{
    return askForName(type, name, kAnyInterface, NameRelay{true, kNameRelays});
}

// The caller's instructions of @p slot's transaction, which got its final
// reply (RemoteInstructions): the counter is read last, as close to the
// return as the record allows. Nothing without a counter, or for a reply
// from a link that does not stamp. Under the lock.
[[gnu::noinline]] void recordCall(const CallSlot& slot)
{
    if (slot.begun == 0 || slot.replyStamp == 0) {
        return;
    }
    RemoteInstructions& counts = statistics.instructions;
    counts.callRequest = static_cast<uint32_t>(slot.queued - slot.begun);
    const uint64_t now = readCounter();
    counts.callReply = static_cast<uint32_t>(now - slot.replyStamp);
    counts.callSpan = now - slot.begun;
}

template <typename Send>
Result<uint32_t> awaitReply(CallSlot& callSlot, uint64_t begun, Send send, uint32_t* errorValue)
{
    CallSlot* const slot = &callSlot;
    slot->begun = begun;
    unsigned silentPeriods = 0;
    for (bool first = true;; first = false) {
        send();
        if (first) {
            slot->queued = readCounter(); // The first request is on the link.
        }
        Lock lock;
        if (!slot->done) {
            (void)TaskManager::blockOn(slot->waiter, kWatchdogNs);
        }
        if (slot->done) {
            const Status status = slot->status;
            const uint32_t value = slot->value;
            slot->caller = ObjectId::null();
            recordCall(*slot);
            if (status != Status::Ok) {
                if (errorValue != nullptr) {
                    *errorValue = value; // A refusal's value says more (kAskHeld).
                }
                return status;
            }
            return value;
        }
        if (slot->heard) {
            slot->heard = false;
            silentPeriods = 0;
        } else if (++silentPeriods >= kRemoteSilentPeriods) {
            slot->caller = ObjectId::null();
            // A name query nobody answers is a name no node has, not a dead node.
            if (slot->service == RemoteService::NameToObject) {
                ++statistics.namesNotFound;
            } else {
                ++statistics.unreachable;
            }
            return Status::Unreachable;
        }
        ++statistics.retransmissions;
    }
}

// A message its decoder refused.
void countMalformed()
{
    Lock lock;
    ++statistics.malformed;
}

// A reply arrived on @p interface from @p source.
void onReply(uint8_t interface, const SystemMessage& message)
{
    RemoteReply reply;
    Lock lock;
    if (decodeReply(message.data, message.length, reply) != RemoteMessageError::None) {
        ++statistics.malformed;
        return;
    }
    const size_t index = reply.transaction & kSlotMask;
    if (index >= kRemoteCalls) {
        ++statistics.strayReplies;
        return;
    }
    CallSlot& slot = calls[index];
    const bool fromPeer = slot.interface == kAnyInterface || (slot.interface == interface && slot.peer == message.source);
    if (slot.caller.isNull() || slot.done || slot.transaction != reply.transaction || !fromPeer ||
        slot.service != reply.service) {
        ++statistics.strayReplies;
        return;
    }
    if (reply.pending) {
        ++statistics.pendingReplies;
        slot.heard = true;
        return;
    }
    ++statistics.replies;
    slot.done = true;
    slot.status = reply.status;
    slot.value = reply.value;
    slot.replyStamp = message.instructionStamp;
    (void)TaskManager::wakeFirst(slot.waiter, Status::Ok);
}

// ---- publications relayed by this node as a gateway ------------------------
//
// A node behind a gateway opens a publisher on the gateway's other bus with
// a routed DsmOpen; the gateway notes the publisher and the interface the
// Open came from, and from then on passes each of the publisher's frames to
// that interface, every frame behind a relay header naming the publisher's
// node (PublicationMessage.hpp). An entry ends with the publisher's
// withdrawal; with every entry in use, a routed Open answers Busy.

struct Relay {
    bool used = false;
    ObjectId publisher;
    uint8_t interface = 0;  // Where its frames go.
};

constexpr size_t kRelays = 8;
Relay relays[kRelays];
size_t relaysInUse = 0; // So a node that relays nothing pays one test per frame.

// Notes that @p publisher's frames go to @p interface; false when the table is full. Under the lock.
bool addRelay(ObjectId publisher, uint8_t interface)
{
    Relay* free = nullptr;
    for (Relay& relay : relays) {
        if (relay.used && relay.publisher == publisher && relay.interface == interface) {
            return true;
        }
        if (!relay.used && free == nullptr) {
            free = &relay;
        }
    }
    if (free == nullptr) {
        return false;
    }
    *free = Relay{true, publisher, interface};
    ++relaysInUse;
    return true;
}

// Ends @p relay. Under the lock.
void endRelay(Relay& relay)
{
    relay.used = false;
    --relaysInUse;
}

void removeRelay(ObjectId publisher, uint8_t interface)
{
    Lock lock;
    for (Relay& relay : relays) {
        if (relay.used && relay.publisher == publisher && relay.interface == interface) {
            endRelay(relay);
        }
    }
}

// Passes a frame of @p publisher, which arrived on @p from after crossing
// @p crossed gateways (0: heard on the publisher's own bus), to every interface
// that asked for it, behind its relay header, at the frame's priority. A
// withdrawal ends the relay.
void relayPublication(uint8_t from, const SystemMessage& message, ObjectId publisher, bool withdrawal,
                      uint8_t crossed = 0)
{
    {
        Lock lock;
        if (relaysInUse == 0) [[likely]] {
            return;
        }
    }
    uint8_t header[kRelayHeaderBytes];
    encodeRelayHeader(publisher.node(), header, crossed);
    for (Relay& relay : relays) {
        uint8_t to;
        {
            Lock lock;
            if (!relay.used || relay.publisher != publisher || relay.interface == from) {
                continue;
            }
            to = relay.interface;
            if (withdrawal) {
                endRelay(relay);
            }
            if (crossed >= kRelayCrossings) {
                // Relays set up in a circle: the frame went as far as any may.
                ++statistics.unrouted;
                continue;
            }
        }
        if (sendBytes(to, SystemMessageType::RelayedPublication, message.priority, NetworkLink::kBroadcast, header,
                      kRelayHeaderBytes) &&
            sendBytes(to, SystemMessageType::RelayedPublication, message.priority, NetworkLink::kBroadcast,
                      message.data, message.length)) {
            Lock lock;
            ++statistics.publicationsRelayed;
        }
    }
}

// The node a relay header named, per sender, for the one frame after it.
struct RelayHeard {
    bool used = false;
    uint8_t interface = 0;
    uint32_t source = 0;
    uint16_t node = 0;
    uint8_t crossedBefore = 0; // Gateways the frame crossed before the one that sent it.
};

RelayHeard relaysHeard[kRelays];

// A publication frame arrived on @p interface.
void onPublication(uint8_t interface, const SystemMessage& message)
{
    PublicationPart part;
    if (decodePublicationPart(message.data, message.length, part) != PublicationMessageError::None) {
        countMalformed();
        return;
    }
    const Result<uint16_t> node = NetworkInterfacesManager::NodeAt(interface, message.source);
    {
        Lock lock;
        ++statistics.publicationParts;
        if (!node.ok()) {
            ++statistics.unknownSenders;
            return;
        }
    }
    DsmManager::deliverPublication(interface, node.value(), part, TimerAgent::Uptime());
    // As a gateway: to the buses that asked for this publisher.
    const ObjectId publisher = publisherOn(node.value(), part.index);
    relayPublication(interface, message, publisher, part.kind == PublicationPartKind::Withdrawal);
}

// ---- a node that starts again ---------------------------------------------------

// Whether this node has announced itself on each interface since it
// started: once per boot, so a link taken down and attached again (the
// node did not restart) says nothing.
bool announced[kNetworkInterfaces] = {};

// The announcement (docs/protocols/remote-transactions.md, "A node that
// starts again"): 8 bytes to the broadcast address, the node's logical id
// big-endian in bytes 0-1, bytes 2-7 zero. At the least urgent priority:
// it is sent once, before the node has asked anybody anything.
constexpr uint8_t kAnnouncementPriority = 31;

// Called by AttachLink, which attaches one interface at a time. A send
// that fails (counted by sendOnLink) leaves the announcement to the next
// attach.
void announceStart(uint8_t interface)
{
    if (announced[interface]) {
        return;
    }
    uint8_t data[kRemoteMessageBytes];
    encodeNodeStarted(NodeStarted{localNode()}, data);
    announced[interface] =
        sendMessage(interface, SystemMessageType::NodeStarted, kAnnouncementPriority, NetworkLink::kBroadcast, data);
}

// ---- pools and heaps lent to nodes that share this node's memory -------------

// Which node holds each buffer and segment lent (RemoteMemoryHolds.hpp). Under the lock.
RemoteMemoryHolds memoryHolds;

// The address of a buffer or segment as a request carries it.
uint32_t addressOf(const void* pointer) { return static_cast<uint32_t>(reinterpret_cast<uintptr_t>(pointer)); }
void* pointerAt(uint32_t address) { return reinterpret_cast<void*>(static_cast<uintptr_t>(address)); }

// Returns @p address, lent, to @p area, a pool or a heap.
Status returnLent(ObjectId area, uint32_t address)
{
    return area.type() == ObjectType::BufferPool ? BufferPoolManager::ReturnLent(area, pointerAt(address))
                                                 : HeapManager::ReturnLent(area, pointerAt(address));
}

// A pool's or heap's Allocate or Return asked by a task of another node:
// performed with the lent tag, the buffer or segment noted as that node's.
// Only for a node that shares this node's memory, over the board's own
// link and not through a gateway: any other could not use the address.
// @p value: the address handed out.
Status serveMemory(const RemoteRequest& request, const ServedEntry& entry, ObjectId area, uint32_t& value)
{
    if (entry.node != localNode() || !withinController(entry.interface)) {
        return Status::NotSupported;
    }
    const Result<uint16_t> requester = NetworkInterfacesManager::NodeAt(entry.interface, entry.source);
    if (!requester.ok()) {
        return Status::NotSupported; // A sender the tables do not name cannot be held to its buffers.
    }
    const uint16_t node = requester.value();
    if (request.service == RemoteService::PoolAllocate || request.service == RemoteService::HeapAllocate) {
        {
            Lock lock;
            if (!memoryHolds.hasRoom()) {
                return Status::Busy;
            }
        }
        const Result<void*> got = request.service == RemoteService::PoolAllocate
                                      ? BufferPoolManager::AllocateLent(area)
                                      : HeapManager::AllocateLent(area, request.argument);
        if (!got.ok()) {
            return got.status();
        }
        bool noted;
        {
            Lock lock;
            noted = memoryHolds.add(area, addressOf(got.value()), node);
            statistics.memoryLent += noted ? 1 : 0;
        }
        if (!noted) {
            // Another worker took the last entry meanwhile: nothing is lent untracked.
            (void)returnLent(area, addressOf(got.value()));
            return Status::Busy;
        }
        value = addressOf(got.value());
        return Status::Ok;
    }
    Status status;
    {
        Lock lock;
        status = memoryHolds.check(area, request.argument, node);
    }
    if (status != Status::Ok) {
        return status;
    }
    status = returnLent(area, request.argument);
    if (status == Status::Ok || status == Status::StaleId || status == Status::Corrupted) {
        // Back, or its pool or heap is gone or disabled: either way no longer lent.
        Lock lock;
        memoryHolds.remove(area, request.argument);
        statistics.memoryReturned += status == Status::Ok ? 1 : 0;
    }
    return status;
}

// Returns everything @p node held of this node's pools and heaps: its tasks
// of before are gone. How many buffers and segments.
size_t reclaimMemoryOf(uint16_t node)
{
    constexpr size_t kBatch = 4;
    size_t reclaimed = 0;
    for (;;) {
        RemoteMemoryHolds::Hold batch[kBatch];
        size_t taken;
        {
            Lock lock;
            taken = memoryHolds.takeHoldsOf(node, batch, kBatch);
        }
        for (size_t i = 0; i < taken; ++i) {
            // A pool or heap deleted meanwhile answers StaleId: nothing to give back.
            (void)returnLent(batch[i].area, batch[i].address);
        }
        reclaimed += taken;
        if (taken < kBatch) {
            return reclaimed;
        }
    }
}

// Another node started: what this node keeps for its tasks of before is
// given up, as when those tasks are found gone (a held semaphore freed and
// its waiters told the holder ended; a timer it owned deleted). Its node
// id comes in the message, not from the physical address, which a gateway
// or the tables could map differently; a malformed announcement, or one of
// this node's own id, is counted malformed and changes nothing.
void onNodeStarted(const SystemMessage& message)
{
    NodeStarted announcement;
    if (decodeNodeStarted(message.data, message.length, announcement) != RemoteMessageError::None ||
        announcement.node == localNode()) {
        countMalformed();
        return;
    }
    const size_t holds = freeHoldsOfNode(announcement.node);
    const size_t timers = TimerManager::dropTimersOwnedOnNode(announcement.node);
    const size_t memory = reclaimMemoryOf(announcement.node);
    Lock lock;
    ++statistics.nodesStarted;
    statistics.memoryReclaimed += static_cast<uint32_t>(memory);
    statistics.holdsFreed += static_cast<uint32_t>(holds);
    statistics.timersOfRestarted += static_cast<uint32_t>(timers);
}

// A relayed publication frame arrived on @p interface: a relay header, or
// the frame it names the node of. A gateway passes it on to the buses
// whose subscribers opened the publisher through it, one crossing more, so
// a publisher is read as many gateways away as a routed Open reaches.
void onRelayedPublication(uint8_t interface, const SystemMessage& message)
{
    uint16_t origin = 0;
    uint8_t crossedBefore = 0;
    RelayHeard* heard = nullptr;
    {
        Lock lock;
        RelayHeard* free = nullptr;
        for (RelayHeard& entry : relaysHeard) {
            if (entry.used && entry.interface == interface && entry.source == message.source) {
                heard = &entry;
            } else if (!entry.used && free == nullptr) {
                free = &entry;
            }
        }
        if (decodeRelayHeader(message.data, message.length, origin, &crossedBefore)) {
            RelayHeard* const slot = heard != nullptr ? heard : (free != nullptr ? free : &relaysHeard[0]);
            *slot = RelayHeard{true, interface, message.source, origin, crossedBefore};
            return;
        }
        if (heard == nullptr) {
            ++statistics.unrouted; // A relayed frame whose header was not heard.
            return;
        }
        origin = heard->node;
        crossedBefore = heard->crossedBefore;
        heard->used = false; // A header names the one frame after it.
    }
    PublicationPart part;
    if (decodePublicationPart(message.data, message.length, part) != PublicationMessageError::None) {
        countMalformed();
        return;
    }
    {
        Lock lock;
        ++statistics.publicationParts;
    }
    DsmManager::deliverPublication(interface, origin, part, TimerAgent::Uptime());
    // As a gateway further on: the frame crossed the sender too, before this one.
    relayPublication(interface, message, publisherOn(origin, part.index),
                     part.kind == PublicationPartKind::Withdrawal, static_cast<uint8_t>(crossedBefore + 1));
}

// ---- the serving side ---------------------------------------------------------

// The served table keeps at most one current entry per caller slot of a
// requester: (interface, source, the transaction's slot bits). A request
// with that entry's transaction number is a retransmission; one with
// another number is the requester's next transaction on that slot (it
// begins one only when it is done with, or gave up, the one before), so
// the entry is never asked for again. Matching by the whole transaction
// number alone would not do: the generation wraps after 16 transactions,
// and an old entry of the same number would answer a new request.
bool sameCallSlot(const ServedEntry& entry, uint8_t interface, uint32_t source, uint8_t transaction, bool relay)
{
    return entry.state != ServedState::Free && !entry.superseded && entry.interface == interface &&
           entry.source == source && (entry.request.transaction & kSlotMask) == (transaction & kSlotMask) &&
           entry.relay == relay;
}

// Whether @p request (with @p payload, null for none) is a retransmission
// of @p entry's, heard at @p nowNs. A retransmission repeats its request
// exactly, and a finished entry's comes within its reply's lifetime. The
// transaction number alone does not say so: a node that restarts begins
// its call slots' generations anew, so its first transactions can carry the
// numbers of its last ones before, and a number met again in another
// request, or long after the requester must have given up on its reply, is
// that requester's new transaction, to be performed, not answered from the
// table.
bool isRetransmission(const ServedEntry& entry, const RemoteRequest& request, const uint8_t* payload,
                      uint64_t nowNs)
{
    static constexpr uint8_t kNoPayload[sizeof entry.payload]{};
    const RemoteRequest& stored = entry.request;
    if (stored.transaction != request.transaction || stored.service != request.service ||
        stored.object != request.object || stored.argument != request.argument ||
        __builtin_memcmp(entry.payload, payload != nullptr ? payload : kNoPayload, sizeof entry.payload) != 0) {
        return false;
    }
    return entry.state != ServedState::Done || nowNs - entry.heardNs < kServedReplyLifetimeNs;
}

// Where a new request goes: the finished entry of the same caller slot,
// else a free entry, else the request completed longest ago. Null when
// every entry is queued or running. O(kRemoteServed), under the lock.
ServedEntry* entryForNewRequest(ServedEntry* sameSlot)
{
    if (sameSlot != nullptr) {
        if (sameSlot->state == ServedState::Done) {
            return sameSlot;
        }
        // Still queued or running for a requester that gave it up: it
        // finishes, but no longer answers for the slot.
        sameSlot->superseded = true;
    }
    ServedEntry* oldestDone = nullptr;
    for (ServedEntry& entry : served) {
        if (entry.state == ServedState::Free) {
            return &entry;
        }
        if (entry.state == ServedState::Done &&
            (oldestDone == nullptr || static_cast<int32_t>(entry.order - oldestDone->order) < 0)) {
            oldestDone = &entry;
        }
    }
    return oldestDone;
}

// A request arrived on @p interface; @p payload, when not null, is a
// name query's name or a port send's message (kPortMessageBytes bytes).
// @p partsBefore: the instructions its earlier frames cost
// (RemoteInstructions::servePartsBefore), 0 for a request of one frame.
// @p node is the node whose object it names (this one, or a routed
// request's destination), @p hopsLeft a routed request's hops left.
// @p relay: a name query sent to this node alone (ServedEntry::relay).
void admitRequest(uint8_t interface, const SystemMessage& message, const RemoteRequest& request,
                  const uint8_t* payload, uint32_t partsBefore, uint16_t node, uint8_t hopsLeft,
                  bool relay = false);

// Requests of several frames being put back together (name queries, port
// sends), one per sender: a sender's entry, or a new one taking the entry
// heard from longest ago. The receiver task only.
template <typename Assembler>
struct Gathering {
    bool used = false;
    uint8_t interface = 0;
    uint32_t source = 0;
    uint32_t heard = 0;
    // The instructions of the parts taken so far, each from its interrupt
    // to the end of its handling (RemoteInstructions::servePartsBefore).
    uint32_t partsInstructions = 0;
    Assembler assembler;
};

// The instructions from @p message's interrupt to now: the receiver's share
// of one frame of a request of several. 0 without a counter.
uint32_t partInstructions(const SystemMessage& message) { return instructionsSince(message.instructionStamp); }

template <typename Assembler, size_t N>
Gathering<Assembler>& gatheringFor(Gathering<Assembler> (&table)[N], uint32_t& clock, uint8_t interface,
                                   uint32_t source)
{
    Gathering<Assembler>* gathering = nullptr;
    for (Gathering<Assembler>& candidate : table) {
        if (candidate.used && candidate.interface == interface && candidate.source == source) {
            gathering = &candidate;
            break;
        }
    }
    if (gathering == nullptr) {
        gathering = &table[0];
        for (Gathering<Assembler>& candidate : table) {
            if (!candidate.used || static_cast<int32_t>(candidate.heard - gathering->heard) < 0) {
                gathering = &candidate;
                if (!candidate.used) {
                    break;
                }
            }
        }
        *gathering = Gathering<Assembler>{};
        gathering->used = true;
        gathering->interface = interface;
        gathering->source = source;
    }
    gathering->heard = clock++;
    return *gathering;
}

// The route headers heard lately (routed requests, RemoteMessage.hpp), by
// requester and transaction: the frames of the request follow the header,
// so the last few are enough. The receiver task only.
struct HeardRoute {
    bool used = false;
    uint8_t interface = 0;
    uint32_t source = 0;
    RouteHeader header;
    uint32_t heard = 0;
};
constexpr size_t kRoutesHeard = 8;
HeardRoute routesHeard[kRoutesHeard];
uint32_t routeClock = 0;

// A route header arrived on @p interface: kept for the request's frames.
void onRouteHeader(uint8_t interface, const SystemMessage& message)
{
    RouteHeader header;
    if (decodeRouteHeader(message.data, message.length, header) != RemoteMessageError::None) {
        countMalformed();
        return;
    }
    HeardRoute* kept = &routesHeard[0];
    for (HeardRoute& route : routesHeard) {
        if (route.used && route.interface == interface && route.source == message.source &&
            route.header.transaction == header.transaction) {
            kept = &route;
            break;
        }
        if (!route.used || static_cast<int32_t>(route.heard - kept->heard) < 0) {
            kept = &route;
        }
    }
    kept->used = true;
    kept->interface = interface;
    kept->source = message.source;
    kept->header = header;
    kept->heard = routeClock++;
}

// The route header of the routed request @p transaction from @p source on
// @p interface, or null when none was heard (the request is dropped).
const RouteHeader* routeOf(uint8_t interface, uint32_t source, uint8_t transaction)
{
    for (const HeardRoute& route : routesHeard) {
        if (route.used && route.interface == interface && route.source == source &&
            route.header.transaction == transaction) {
            return &route.header;
        }
    }
    return nullptr;
}

// Admits @p request from @p message, for this node's object or, when it
// was @p routed, for the node its route header named; a routed request
// whose header was not heard is dropped and counted.
void admitFor(uint8_t interface, const SystemMessage& message, const RemoteRequest& request, bool routed,
              const uint8_t* payload, uint32_t partsBefore)
{
    if (!routed) {
        admitRequest(interface, message, request, payload, partsBefore, localNode(), 0);
        return;
    }
    const RouteHeader* const route = routeOf(interface, message.source, request.transaction);
    if (route == nullptr) {
        Lock lock;
        ++statistics.unrouted;
        return;
    }
    admitRequest(interface, message, request, payload, partsBefore, route->destination, route->hopsLeft);
}

constexpr size_t kRequestsGathered = 4;
Gathering<NameQueryAssembler> nameQueries[kRequestsGathered];
Gathering<NameQueryAssembler> relayedNameQueries[kRequestsGathered];
Gathering<ContinuedRequestAssembler> portSends[kRequestsGathered];
uint32_t gatheringClock = 0;

// A request arrived on @p interface: one frame, or a part of a port send;
// @p routed when it came as a routed request's frame.
void onRequest(uint8_t interface, const SystemMessage& message, bool routed)
{
    if (isContinuation(message.data, message.length)) {
        Continuation part;
        if (decodeContinuation(message.data, message.length, part) != RemoteMessageError::None) {
            countMalformed();
            return;
        }
        Gathering<ContinuedRequestAssembler>& gathering = gatheringFor(portSends, gatheringClock, interface, message.source);
        if (gathering.assembler.take(part) != ContinuedRequestAssembler::Outcome::Complete) {
            gathering.partsInstructions += partInstructions(message);
            return; // In turn and not the last, or out of turn and dropped: the requester sends it again.
        }
        if (gathering.assembler.service() == RemoteService::HeldAcquire) {
            const HeldAcquireRequest held = gathering.assembler.heldAcquire();
            RemoteRequest request;
            request.service = RemoteService::HeldAcquire;
            request.transaction = held.transaction;
            request.object = held.object;
            request.argument = held.timeoutMs;
            // The holder rides in the entry's payload, big-endian.
            uint8_t payload[kPortMessageBytes]{};
            payload[0] = static_cast<uint8_t>(held.holder >> 24);
            payload[1] = static_cast<uint8_t>(held.holder >> 16);
            payload[2] = static_cast<uint8_t>(held.holder >> 8);
            payload[3] = static_cast<uint8_t>(held.holder);
            admitFor(interface, message, request, routed, payload, gathering.partsInstructions);
            return;
        }
        // A port send or an alarm, laid out alike: byte 4 (the message's
        // priority, an alarm's flags) as the argument, the sixteen bytes as
        // the payload. An alarm whose flags are not defined is malformed.
        AlarmRequest alarm;
        if (gathering.assembler.service() == RemoteService::TimerSetAlarm && !gathering.assembler.alarm(alarm)) {
            countMalformed();
            return;
        }
        const PortSendRequest whole = gathering.assembler.portSend();
        RemoteRequest request;
        request.service = gathering.assembler.service();
        request.transaction = whole.transaction;
        request.object = whole.object;
        request.argument = static_cast<uint8_t>(whole.priority);
        admitFor(interface, message, request, routed, whole.message, gathering.partsInstructions);
        return;
    }
    RemoteRequest request;
    if (decodeRequest(message.data, message.length, request) != RemoteMessageError::None ||
        request.service == RemoteService::NameToObject) {
        // NameToObject comes only as a name query.
        countMalformed();
        return;
    }
    if (request.service == RemoteService::PortSend || request.service == RemoteService::HeldAcquire ||
        request.service == RemoteService::TimerSetAlarm) {
        Gathering<ContinuedRequestAssembler>& gathering = gatheringFor(portSends, gatheringClock, interface, message.source);
        (void)gathering.assembler.start(request);
        gathering.partsInstructions = partInstructions(message);
        return;
    }
    admitFor(interface, message, request, routed, nullptr, 0);
}

// A part of a name query arrived on @p interface (the receiver task only).
void onNameQuery(uint8_t interface, const SystemMessage& message)
{
    NameQueryPart part;
    if (decodeNameQueryPart(message.data, message.length, part) != NameQueryError::None) {
        countMalformed();
        return;
    }
    // Sent to this node alone, not broadcast: it is asked as a gateway. A
    // requester sends such a query beside its broadcast one, and the two
    // streams' frames may interleave on the bus, so each is put together apart.
    const bool relay = message.destination != NetworkLink::kBroadcast;
    Gathering<NameQueryAssembler>& gathering =
        gatheringFor(relay ? relayedNameQueries : nameQueries, gatheringClock, interface, message.source);
    if (!gathering.assembler.take(part)) {
        return;
    }
    if (!relay && gathering.assembler.relays() != 0) {
        countMalformed(); // Only a query to a gateway alone is passed on.
        return;
    }
    RemoteRequest request;
    request.service = RemoteService::NameToObject;
    request.transaction = gathering.assembler.transaction();
    request.object = gathering.assembler.type();
    request.argument = gathering.assembler.relays();
    admitRequest(interface, message, request, reinterpret_cast<const uint8_t*>(gathering.assembler.name()), 0,
                 localNode(), 0, relay);
}

// A request to serve: a retransmission is answered from the served table,
// a new one queued for the workers.
void admitRequest(uint8_t interface, const SystemMessage& message, const RemoteRequest& request,
                  const uint8_t* payload, uint32_t partsBefore, uint16_t node, uint8_t hopsLeft, bool relay)
{
    RemoteReply answer;
    answer.service = request.service;
    answer.transaction = request.transaction;
    uint8_t stored[kRemoteMessageBytes];
    enum class Action : uint8_t { None, Pending, Stored, Busy } action = Action::None;
    {
        Lock lock;
        ServedEntry* sameSlot = nullptr;
        for (ServedEntry& entry : served) {
            if (sameCallSlot(entry, interface, message.source, request.transaction, relay)) {
                sameSlot = &entry;
                break;
            }
        }
        const uint64_t nowNs = TimerAgent::Uptime();
        ServedEntry* const known =
            sameSlot != nullptr && isRetransmission(*sameSlot, request, payload, nowNs) ? sameSlot : nullptr;
        if (known != nullptr) {
            ++statistics.duplicates;
            known->heardNs = nowNs;
            if (known->state == ServedState::Done) {
                __builtin_memcpy(stored, known->reply, kRemoteMessageBytes);
                action = known->silent ? Action::None : Action::Stored;
            } else {
                action = Action::Pending;
            }
        } else {
            ServedEntry* entry = entryForNewRequest(sameSlot);
            if (entry == nullptr) {
                ++statistics.refusedBusy;
                action = Action::Busy;
            } else {
                entry->state = ServedState::Queued;
                entry->superseded = false;
                entry->silent = false;
                if (payload != nullptr) {
                    __builtin_memcpy(entry->payload, payload, sizeof entry->payload);
                } else {
                    __builtin_memset(entry->payload, 0, sizeof entry->payload);
                }
                entry->interface = interface;
                entry->priority = message.priority;
                entry->source = message.source;
                entry->request = request;
                entry->order = arrivals++;
                entry->heardNs = nowNs;
                entry->arrivalStamp = message.instructionStamp;
                entry->partsBefore = partsBefore;
                entry->node = node;
                entry->hopsLeft = hopsLeft;
                entry->relay = relay;
                // The worker takes the request's priority as it wakes, not
                // when it first runs: woken at its idle priority, it would
                // wait behind every local task, however urgent the request.
                Task* const worker = TaskManager::wakeFirst(idleWorkers, Status::Ok);
                if (worker != nullptr) {
                    (void)TaskManager::changePriority(*worker, message.priority);
                }
            }
        }
    }
    switch (action) {
    case Action::None: break;
    case Action::Pending:
        answer.pending = true;
        sendReply(interface, message.priority, message.source, answer);
        break;
    case Action::Busy:
        answer.status = Status::Busy;
        sendReply(interface, message.priority, message.source, answer);
        break;
    case Action::Stored:
        (void)sendMessage(interface, SystemMessageType::RemoteReply, message.priority, message.source, stored);
        break;
    }
}

// A remote Acquire that may wait: in slices of kRequesterSilenceNs, so
// that a wait whose requester has gone silent ends (Timeout) within one
// slice rather than holding a worker for ever. Between two slices the
// worker joins the semaphore's waiters again, behind those of its priority.
Status acquireForRequester(ObjectId id, uint32_t timeoutMs, const ServedEntry& entry, bool probeHolder = false)
{
    const bool forever = timeoutMs == kRemoteForever;
    const uint64_t end = forever ? 0 : TimerAgent::Uptime() + remoteTimeoutNs(timeoutMs);
    for (;;) {
        uint64_t slice = kRequesterSilenceNs;
        if (!forever) {
            const uint64_t now = TimerAgent::Uptime();
            if (now >= end) {
                return Status::Timeout;
            }
            slice = end - now < slice ? end - now : slice;
        }
        const Status status = SemaphoreAgent::Acquire(id, slice);
        if (status != Status::Timeout) {
            return status;
        }
        {
            Lock lock;
            if (TimerAgent::Uptime() - entry.heardNs > kRequesterSilenceNs) {
                ++statistics.abandoned;
                return Status::Timeout;
            }
        }
        // A binary semaphore held by a task of another node: is it still there?
        if (probeHolder && probeRemoteHolder(id)) {
            return Status::Abandoned;
        }
    }
}

// A held acquire of @p id for @p holder, a task of another node. Counting
// semaphores have no holder: their Acquire is served as the plain form's.
// A binary one is acquired by this worker, in slices as above, with its
// remote holder probed between them; then handed to @p holder.
Status acquireHeld(ObjectId id, uint32_t timeoutMs, ObjectId holder, const ServedEntry& entry)
{
    const Result<bool> binary = isBinarySemaphore(id);
    if (!binary.ok()) {
        return binary.status();
    }
    if (binary.value() && remoteHolderOf(id) == holder) {
        return Status::Deadlock; // The holder asks again for what it holds.
    }
    const Status status = timeoutMs == kRemotePoll ? SemaphoreAgent::Acquire(id, kPoll)
                                                   : acquireForRequester(id, timeoutMs, entry, binary.value());
    if (status != Status::Ok || !binary.value()) {
        return status;
    }
    return holdForRemote(id, holder);
}

// An alarm set by a timer's owner on another node: refused unless the task
// it names owns the timer (a worker's own privileges are not the owner's),
// then set as the owner would set it locally; a routed one is passed on.
Status serveAlarm(const RemoteRequest& request, const ServedEntry& entry, ObjectId id, bool routed)
{
    // The flags were checked as the alarm came in (onRequest).
    AlarmRequest alarm;
    if (!decodeAlarmRecord(static_cast<uint8_t>(request.argument), entry.payload, alarm)) {
        return Status::InvalidArgument;
    }
    const ObjectId owner = ObjectId::fromRaw(alarm.owner);
    const AlarmNotification notification{
        alarm.signal ? AlarmNotification::Kind::Signal : AlarmNotification::Kind::Event, alarm.value};
    const uint64_t timeNs = alarm.timeNs;
    const RemoteAlarmKind kind = alarm.kind;
    if (routed) {
        return callAlarm(id, kind, notification, timeNs, owner);
    }
    const Result<ObjectId> current = TimerManager::timerOwner(id);
    if (!current.ok()) {
        return current.status();
    }
    if (current.value() != owner) {
        return Status::NotOwner;
    }
    switch (kind) {
    case RemoteAlarmKind::WatchDog: return TimerManager::setWatchDogAlarm(id, owner, timeNs, notification);
    case RemoteAlarmKind::Periodic: return TimerManager::setPeriodicAlarm(id, owner, timeNs, notification);
    case RemoteAlarmKind::DayClock: break;
    }
    return TimerManager::setDayClockAlarm(id, owner, GregorianCalendar::fromNanoseconds(timeNs), notification);
}

// ---- alarms of this node's timers owned by tasks of other nodes --------------
//
// The tick's interrupt queues each notification here (RemoteForward.hpp's
// alarm queue); the notifier task posts it to the owner as a remote
// PostEvent or SendSignal. An owner that no longer exists, or whose node
// does not answer, has its timer deleted, as a local owner's death does.

struct AlarmNotice {
    ObjectId timer;
    ObjectId owner;
    AlarmNotification notification;
};

constexpr size_t kAlarmNotices = 16;
AlarmNotice alarmNotices[kAlarmNotices];
size_t alarmHead = 0;  // The next notice to send.
size_t alarmCount = 0;
ObjectId notifierTask;
constexpr uint32_t kAlarmEvent = 1;

// From the tick's interrupt (interrupts disabled) or a task.
void queueAlarm(ObjectId timer, ObjectId owner, const AlarmNotification& notification)
{
    Lock lock;
    if (alarmCount == kAlarmNotices) {
        ++statistics.alarmsDropped;
        return;
    }
    alarmNotices[(alarmHead + alarmCount) % kAlarmNotices] = AlarmNotice{timer, owner, notification};
    ++alarmCount;
    const Result<Task*> notifier = TaskManager::resolve(notifierTask);
    if (notifier.ok()) {
        TaskManager::postEvent(*notifier.value(), kAlarmEvent);
    }
}

void notifierEntry(uintptr_t)
{
    for (;;) {
        AlarmNotice notice;
        {
            Lock lock;
            if (alarmCount == 0) {
                notice.timer = ObjectId::null();
            } else {
                notice = alarmNotices[alarmHead];
                alarmHead = (alarmHead + 1) % kAlarmNotices;
                --alarmCount;
            }
        }
        if (notice.timer.isNull()) {
            (void)TaskAgent::ReceiveEvent(kAlarmEvent, EventWait::Any, kWaitForever);
            continue;
        }
        const Status status = notice.notification.kind == AlarmNotification::Kind::Signal
                                  ? TaskAgent::SendSignal(notice.owner, notice.notification.value)
                                  : TaskAgent::PostEvent(notice.owner, notice.notification.value);
        Lock lock;
        if (status == Status::Ok) {
            ++statistics.alarmsNotified;
        } else if (status == Status::InvalidId || status == Status::StaleId || status == Status::Unreachable) {
            ++statistics.alarmOwnersLost;
            TimerManager::dropTimerOfLostOwner(notice.timer, notice.owner);
        } else {
            ++statistics.alarmsDropped; // Not told (no call slot free, the node unmapped): lost, counted.
        }
    }
}

// A read service's result as the reply's status and value.
uint32_t replyValueOf(uint32_t value) { return value; }
uint32_t replyValueOf(uint8_t value) { return value; }
uint32_t replyValueOf(TaskState state) { return static_cast<uint32_t>(state); }
uint32_t replyValueOf(ObjectId id) { return id.raw(); }

template <typename T>
void replyWith(RemoteReply& reply, const Result<T>& result)
{
    reply.status = result.status();
    reply.value = result.ok() ? replyValueOf(result.value()) : 0;
}

// Performs @p request on this node's object, as the worker that runs it;
// marks @p entry silent when there is nothing to answer.
RemoteReply perform(const RemoteRequest& request, ServedEntry& entry)
{
    RemoteReply reply;
    reply.service = request.service;
    reply.transaction = request.transaction;
    // A routed request names another node's object: the primitive below
    // takes the id's miss path and forwards it there, as its own remote
    // transaction, at the requester's priority.
    const bool routed = entry.node != localNode();
    if (routed) {
        Lock lock;
        ++statistics.forwarded;
    }
    const ObjectId id = request.objectOn(entry.node);
    switch (request.service) {
    case RemoteService::SemaphoreAcquire:
    case RemoteService::SemaphoreRelease: {
        // A binary semaphore is held by a task, so the requester must name
        // it: the plain form is answered kAskHeld, and the requester asks
        // again with the held form (docs/protocols/remote-transactions.md,
        // "Binary semaphores"). A routed request's node decides that for
        // itself; its refusal is passed back as it came.
        const Result<bool> binary = routed ? Result<bool>(false) : isBinarySemaphore(id);
        if (!binary.ok()) {
            reply.status = binary.status();
        } else if (binary.value()) {
            reply.status = Status::NotSupported;
        } else if (request.service == RemoteService::SemaphoreAcquire) {
            reply.status = request.argument == kRemotePoll ? SemaphoreAgent::Acquire(id, kPoll)
                                                           : acquireForRequester(id, request.argument, entry);
        } else {
            reply.status = SemaphoreAgent::Release(id);
        }
        if (reply.status == Status::NotSupported) {
            // The one refusal of these two services that says NotSupported,
            // here or on a routed request's node.
            reply.value = kAskHeld;
        }
        break;
    }
    case RemoteService::TimerSetAlarm: reply.status = serveAlarm(request, entry, id, routed); break;
    case RemoteService::TimerCancelAlarm: {
        const ObjectId owner = ObjectId::fromRaw(request.argument);
        if (routed) {
            replyWith(reply, call(RemoteService::TimerCancelAlarm, id, request.argument, ObjectId::null()));
            break;
        }
        const Result<ObjectId> current = TimerManager::timerOwner(id);
        reply.status = !current.ok()              ? current.status()
                       : current.value() != owner ? Status::NotOwner
                                                  : TimerManager::cancelAlarm(id, owner);
        break;
    }
    case RemoteService::HeldAcquire:
    case RemoteService::HeldRelease: {
        const ObjectId holder = request.service == RemoteService::HeldRelease
                                    ? ObjectId::fromRaw(request.argument)
                                    : ObjectId::fromRaw((uint32_t{entry.payload[0]} << 24) |
                                                        (uint32_t{entry.payload[1]} << 16) |
                                                        (uint32_t{entry.payload[2]} << 8) | entry.payload[3]);
        if (holder.type() != ObjectType::Task || holder.node() == localNode()) {
            // A holder is a task of another node. Which one, the requester
            // says: through a gateway the request comes from the gateway, so
            // its sender's node is not the holder's.
            reply.status = Status::InvalidArgument;
        } else if (routed) {
            // Passed on in the held form, naming the same task.
            replyWith(reply, call(request.service, id, request.argument, holder));
        } else if (request.service == RemoteService::HeldRelease) {
            reply.status = releaseForRemote(id, holder);
        } else {
            reply.status = acquireHeld(id, request.argument, holder, entry);
        }
        break;
    }
    case RemoteService::SemaphoreGetCount: replyWith(reply, SemaphoreAgent::GetCount(id)); break;
    case RemoteService::PostEvent: reply.status = TaskAgent::PostEvent(id, request.argument); break;
    case RemoteService::SendSignal: reply.status = TaskAgent::SendSignal(id, request.argument); break;
    case RemoteService::TaskGetState: replyWith(reply, TaskAgent::GetState(id)); break;
    case RemoteService::TaskGetPriority: replyWith(reply, TaskAgent::GetPriority(id)); break;
    case RemoteService::SemaphoreGetHolder: replyWith(reply, SemaphoreAgent::GetHolder(id)); break;
    case RemoteService::NameToObject: {
        // Seen from another node, a name is visible when its object is global,
        // or regional and asked for within the controller (Visibility.hpp).
        const Visibility scope = withinController(entry.interface) ? Visibility::Regional : Visibility::Global;
        // The assembler let through only names of 1 to 15 characters, NUL-padded.
        const ObjectType type = static_cast<ObjectType>(request.object);
        const char* const name = reinterpret_cast<const char*>(entry.payload);
        Result<ObjectId> found = localNameToObject(type, name, scope);
        if (!found.ok() && entry.relay) {
            // Asked as a gateway: the buses beyond, not the one it came
            // from, and with relays left the routes' gateways, but not the
            // one that asked, each with one relay fewer.
            const uint8_t relaysLeft = static_cast<uint8_t>(request.argument);
            const NameRelay further{relaysLeft > 0, static_cast<uint8_t>(relaysLeft > 0 ? relaysLeft - 1 : 0),
                                    entry.interface, entry.source};
            found = askForName(type, name, entry.interface, further);
            if (found.ok()) {
                Lock lock;
                ++statistics.forwarded;
            }
        }
        if (found.ok()) {
            reply.value = found.value().raw();
        } else {
            entry.silent = true; // Another node may have it; this one says nothing.
        }
        break;
    }
    case RemoteService::DsmOpen: {
        if (routed) {
            // As a gateway: the publisher's frames are relayed to the bus the
            // Open came from from now on, and the gateway opens it itself,
            // so its node sends its latest page again, relayed too. For a
            // publisher behind a further gateway that Open is routed on, and
            // that gateway relays the frames to this one's bus, from where
            // this one relays them again (onRelayedPublication).
            {
                Lock lock;
                if (!addRelay(id, entry.interface)) {
                    reply.status = Status::Busy;
                    break;
                }
            }
            replyWith(reply, call(RemoteService::DsmOpen, id, 0, ObjectId::null()));
            if (reply.status != Status::Ok) {
                removeRelay(id, entry.interface);
            }
            break;
        }
        replyWith(reply, DsmManager::serveRemoteOpen(id, withinController(entry.interface)));
        break;
    }
    case RemoteService::PoolAllocate:
    case RemoteService::PoolReturn:
    case RemoteService::HeapAllocate:
    case RemoteService::HeapReturn: reply.status = serveMemory(request, entry, id, reply.value); break;
    case RemoteService::PortSend: {
        // Sent as any local task sends: the port's own checks (priority,
        // buffers, deletion) answer for it.
        Message message;
        __builtin_memcpy(message.bytes, entry.payload, kPortMessageBytes);
        reply.status = MessagePortAgent::Send(id, message, static_cast<int8_t>(request.argument));
        break;
    }
    }
    // The object is this node's, so a Remote status cannot come back; were
    // it to, the requester must not take it for its own "no network". For a
    // routed request it means this gateway's tables do not know the node.
    if (reply.status == Status::Remote) {
        reply.status = routed ? Status::Unreachable : Status::InvalidId;
    }
    return reply;
}

// The most urgent queued request, first come first served among equals. Under the lock.
ServedEntry* mostUrgentQueued()
{
    ServedEntry* best = nullptr;
    for (ServedEntry& entry : served) {
        if (entry.state == ServedState::Queued &&
            (best == nullptr || entry.priority < best->priority ||
             (entry.priority == best->priority && static_cast<int32_t>(entry.order - best->order) < 0))) {
            best = &entry;
        }
    }
    return best;
}

// The serving side's instructions of a request just answered
// (RemoteInstructions): from @p arrived, its last frame's stamp, to now,
// plus @p partsBefore. Nothing without a counter. The counter is read
// before the lock is taken, so the figure ends with the reply on the link.
[[gnu::noinline]] void recordServe(uint64_t arrived, uint32_t partsBefore)
{
    if (arrived == 0) {
        return;
    }
    const uint32_t serve = instructionsSince(arrived) + partsBefore;
    Lock lock;
    statistics.instructions.serve = serve;
    statistics.instructions.servePartsBefore = partsBefore;
}

void workerEntry(uintptr_t index)
{
    Task& self = Scheduler::current();
    {
        Lock lock;
        workerIds[index] = self.id;
    }
    for (;;) {
        ServedEntry* job;
        RemoteRequest request;
        uint8_t interface;
        uint8_t priority;
        uint32_t source;
        uint64_t arrivalStamp;
        uint32_t partsBefore;
        {
            Lock lock;
            job = mostUrgentQueued();
            if (job == nullptr) {
                (void)TaskManager::blockOn(idleWorkers, kWaitForever);
                continue;
            }
            job->state = ServedState::Running;
            workerJobs[index] = job;
            request = job->request;
            interface = job->interface;
            priority = job->priority;
            source = job->source;
            arrivalStamp = job->arrivalStamp;
            partsBefore = job->partsBefore;
            ++statistics.served;
        }
        // Inherit the request's priority (seed 6.4): local tasks more
        // urgent than the requester keep the processor.
        (void)TaskManager::changePriority(self, priority);
        const RemoteReply reply = perform(request, *job);
        bool silent;
        {
            Lock lock;
            encodeReply(reply, job->reply);
            workerJobs[index] = nullptr;
            job->state = ServedState::Done;
            job->order = completions++;
            silent = job->silent;
        }
        if (!silent) {
            sendReply(interface, priority, source, reply);
            recordServe(arrivalStamp, partsBefore);
        }
    }
}

// A frame of the flash or the configuration protocol goes to the system
// engineering interface agent, in the images that link it
// (firmware/flash/src/FlashService.cpp); the others drop it.
void onEngineeringFrame(uint8_t interface, const SystemMessage& message)
{
    if (flashServiceFrame != nullptr) {
        flashServiceFrame(interface, message);
    } else {
        ++statistics.noFlashService;
    }
}

void receiverEntry(uintptr_t)
{
    constexpr uint32_t kAllLinks = (kNetworkInterfaces >= 32) ? ~0u : ((1u << kNetworkInterfaces) - 1);
    for (;;) {
        const Result<uint32_t> events =
            TaskAgent::ReceiveEvent(kAllLinks | kDeferredPublicationsEvent, EventWait::Any, kWaitForever);
        if (!events.ok()) {
            continue;
        }
        if ((events.value() & kDeferredPublicationsEvent) != 0) {
            DsmManager::publishDeferred();
        }
        for (uint8_t interface = 0; interface < kNetworkInterfaces; ++interface) {
            if ((events.value() & eventOf(interface)) == 0) {
                continue;
            }
            NetworkLink* link;
            {
                Lock lock;
                link = links[interface];
            }
            if (link == nullptr) {
                continue;
            }
            // Every waiting message, in arrival order; the driver's queue
            // is bounded, so is this loop.
            SystemMessage message;
            for (;;) {
                const Result<bool> got = link->Receive(message);
                if (!got.ok() || !got.value()) {
                    break;
                }
                switch (message.type) {
                case SystemMessageType::RemoteReply: onReply(interface, message); break;
                case SystemMessageType::RemoteRequest: onRequest(interface, message, false); break;
                case SystemMessageType::RoutedRequest:
                    if (isRouteHeader(message.data, message.length)) {
                        onRouteHeader(interface, message);
                    } else {
                        onRequest(interface, message, true);
                    }
                    break;
                case SystemMessageType::NameQuery: onNameQuery(interface, message); break;
                case SystemMessageType::DsmPublication: onPublication(interface, message); break;
                case SystemMessageType::RelayedPublication: onRelayedPublication(interface, message); break;
                case SystemMessageType::NodeStarted: onNodeStarted(message); break;
                case SystemMessageType::TimeSync: onTimeSyncMessage(interface, message); break;
                case SystemMessageType::Flashing:
                case SystemMessageType::Configuration: onEngineeringFrame(interface, message); break;
                case SystemMessageType::Monitoring:
                    // A stream goes from a node to a host; the link never
                    // passes one up, and another node's is nothing to act on.
                    break;
                }
            }
        }
    }
}

// Creates the receiver and the workers on first use. A start that failed
// part way (no task slot, no stack) resumes where it stopped on the next
// attach, so no task is made twice.
// One of the agent's own tasks, in a process of its own.
Result<ObjectId> createAgentTask(const char* name, uint8_t priority, TaskEntry entry, uintptr_t argument)
{
    TaskAttributes attributes;
    attributes.name = name;
    attributes.priority = priority;
    attributes.stackSize = kTaskStackBytes;
    attributes.newProcess = true;
    return TaskManager::create(attributes, entry, argument);
}

Status startAgent()
{
    static size_t workersCreated = 0;
    if (started) {
        return Status::Ok;
    }
    if (receiverTask.isNull()) {
        const Result<ObjectId> receiverId = createAgentTask("net-receiver", 0, receiverEntry, 0);
        if (!receiverId.ok()) {
            return receiverId.status();
        }
        receiverTask = receiverId.value();
    }
    for (; workersCreated < kRemoteWorkers; ++workersCreated) {
        const Result<ObjectId> workerId = createAgentTask("net-worker", kLowestPriority, workerEntry, workersCreated);
        if (!workerId.ok()) {
            return workerId.status();
        }
    }
    if (notifierTask.isNull()) {
        // Alarms are urgent: the notifier asks at a high priority, on the
        // bus too, below the receiver only.
        const Result<ObjectId> notifierId = createAgentTask("net-alarms", 1, notifierEntry, 0);
        if (!notifierId.ok()) {
            return notifierId.status();
        }
        notifierTask = notifierId.value();
    }
    setRemoteForwarder(forward);
    setRemoteNameResolver(forwardName);
    setRemotePortSender(forwardPortSend);
    setRemoteAlarmSetter(forwardAlarm);
    setRemoteAlarmQueue(queueAlarm);
    started = true;
    return Status::Ok;
}

} // namespace

RemoteStatistics remoteStatistics()
{
    Lock lock;
    return statistics;
}

bool remoteAgentStarted() { return started; }

RemoteCallInfo remoteCall(size_t slot)
{
    RemoteCallInfo info;
    if (slot >= kRemoteCalls) {
        return info;
    }
    Lock lock;
    const CallSlot& call = calls[slot];
    // A caller killed while it waited leaves its slot until a call takes it back.
    info.inUse = !call.caller.isNull() && TaskManager::resolve(call.caller).ok();
    info.caller = call.caller;
    info.service = call.service;
    info.transaction = call.transaction;
    info.interface = call.interface;
    info.peer = call.peer;
    return info;
}

void sendPublication(ObjectId publisher, Visibility visibility, uint32_t dataId, const DsmPage& page,
                     uint8_t priority)
{
    uint8_t frames[kPublicationFrames][kPublicationFrameBytes];
    encodePublication(publicationIndexOf(publisher), dataId, page, frames);
    for (uint8_t interface = 0; interface < kNetworkInterfaces; ++interface) {
        if (!reaches(visibility, interface)) {
            continue;
        }
        // The three parts in a row: a part the link did not take leaves a
        // publication the receivers drop, so the rest is not sent.
        bool whole = true;
        for (size_t part = 0; part < kPublicationFrames && whole; ++part) {
            whole = sendBytes(interface, SystemMessageType::DsmPublication, priority, NetworkLink::kBroadcast,
                              frames[part], kPublicationFrameBytes);
        }
        if (whole) {
            Lock lock;
            ++statistics.publicationsSent;
        }
    }
}

void sendWithdrawal(ObjectId publisher, Visibility visibility, uint8_t priority)
{
    uint8_t frame[kWithdrawalBytes];
    encodeWithdrawal(publicationIndexOf(publisher), frame);
    for (uint8_t interface = 0; interface < kNetworkInterfaces; ++interface) {
        if (reaches(visibility, interface) &&
            sendBytes(interface, SystemMessageType::DsmPublication, priority, NetworkLink::kBroadcast, frame,
                      kWithdrawalBytes)) {
            Lock lock;
            ++statistics.publicationsSent;
        }
    }
}

void requestDeferredPublications()
{
    if (started) {
        (void)TaskAgent::PostEvent(receiverTask, kDeferredPublicationsEvent);
    }
}

bool sendOnLink(uint8_t interface, const SystemMessage& message)
{
    if (interface >= kNetworkInterfaces) {
        return false;
    }
    NetworkLink* link;
    {
        Lock lock;
        link = links[interface];
    }
    if (link == nullptr) {
        return false;
    }
    if (link->Send(message) != Status::Ok) {
        Lock lock;
        ++statistics.sendFailures;
        return false;
    }
    return true;
}

void detachRemoteLink(uint8_t interface)
{
    if (interface >= kNetworkInterfaces) {
        return;
    }
    NetworkLink* link;
    {
        Lock lock;
        link = links[interface];
        links[interface] = nullptr;
    }
    if (link != nullptr) {
        link->Stop();
    }
}

} // namespace internal

Status NetworkInterfacesManager::AttachLink(uint8_t interface, NetworkLink& link)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    const Result<NetworkInterface> entry = GetInterface(interface);
    if (!entry.ok()) {
        return entry.status();
    }
    const Status agent = internal::startAgent();
    if (agent != Status::Ok) {
        return agent;
    }
    {
        // Listed before it starts, so the receiver finds the link for the
        // first event it posts; it sends nothing until started.
        internal::Lock lock;
        if (internal::links[interface] != nullptr) {
            return Status::AlreadyExists;
        }
        internal::links[interface] = &link;
    }
    const Status start =
        link.Start(internal::receiverTask, internal::eventOf(interface), entry.value().physical);
    if (start != Status::Ok) {
        internal::Lock lock;
        internal::links[interface] = nullptr;
        return start;
    }
    internal::announceStart(interface);
    return Status::Ok;
}

Status NetworkInterfacesManager::DetachLink(uint8_t interface)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    {
        internal::Lock lock;
        if (interface >= internal::kNetworkInterfaces || internal::links[interface] == nullptr) {
            return Status::NotFound;
        }
    }
    internal::detachRemoteLink(interface);
    return Status::Ok;
}

} // namespace dcos
