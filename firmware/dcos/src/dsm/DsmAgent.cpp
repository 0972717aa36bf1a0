// The distributed shared memory agent, local part (seed 7.10): its
// interface object and kernel side.
//
// Publishers sit in a static array beside their object table. Each holds
// its 16-byte page, the data identifier of the last Write and the readers
// waiting for a newer one; a waiting reader's Task::waitData points at a
// ReadRequest in its own stack frame, which Write fills before waking it.
// All of a Read's wait state is thus in the publisher, where a request from
// the network can drive it later.
//
// Subscriptions are objects of their own table, owned by the reader. A
// subscription records its publisher's id and the publisher slot's
// incarnation, a count that every Delete of the slot advances and nothing
// resets. Deleting a publisher therefore invalidates all its subscriptions
// in O(1), without finding them, and even a table too large for generation
// bits in its ids (4096 slots) cannot route an old subscription to a new
// publisher in the same slot. The count wraps after 2^32 deletes of one
// slot, which no controller reaches.
//
// Strict consistency (multiple readers, single writer): every access to a
// page, the Write into the publisher, a Read out of it and the hand-over to
// a waiting reader, copies the 16 bytes and the data identifier together
// with interrupts disabled (arch_x86::InterruptGuard). On this uniprocessor
// nothing else runs meanwhile, neither another task nor an interrupt
// handler, so each copy is atomic with respect to every other: a reader
// sees the whole page of one Write, with that Write's identifier, never a
// mix of two. The copy is a fixed 16 bytes, so holding interrupts off for it
// costs O(1). The dual-processor board will need a spinlock around the same
// critical sections.
//
// Publications over the network (seed 7.10, Fig. 7.12;
// docs/protocols/publications.md). A publisher of Global visibility is
// published on every attached link at each Write, at the writer's
// priority, after the local hand-over and with interrupts enabled (an
// interrupt handler's Write is published by the network receiver task, as
// it cannot use a driver). The other side keeps remote publishers: a
// subscription to another node's publisher points at one of them, a
// PublisherObject like a local one, so Read is the same code, fast path
// included. The network receiver task fills it from the frames it
// reassembles, once per publication whichever bus brought it first.
#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/DsmManager.hpp>
#include <dcos/internal/FastPath.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/ObjectTable.hpp>
#include <dcos/internal/ResourceRecovery.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/WaitQueue.hpp>
#include <dcos/internal/ConfigurationService.hpp>
#include <dcos/internal/PublicationMessage.hpp>
#include <dcos/internal/RemoteAgent.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/TimerAgent.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos::internal {

namespace {

// Why a Write cannot take the fast path: the publisher is being deleted,
// or its Writes go out on the network too.
constexpr uint8_t kDying = 0x01;     ///< Being deleted: refused as stale while its readers are woken.
constexpr uint8_t kNetworked = 0x02; ///< Global visibility: every Write is published on the links.

struct PublisherObject {
    ObjectId id;
    uint8_t slowWrite = 0;    ///< kDying, kNetworked.
    bool publishPending = false; ///< An interrupt handler wrote it; the network receiver publishes it.
    uint8_t priority = 0;     ///< The last writing task's priority: the bus priority of its publications.
    Visibility visibility = Visibility::Local;
    uint32_t incarnation = 0; ///< Advanced by every Delete of this slot; never reset.
    uint32_t dataId = kNoDsmData;
    DsmPage page{};
    // First come first served, so the readers waiting for a Write stay ahead
    // of those that wait again after it (see Write).
    WaitQueue readers{WaitQueue::Order::Fifo};
};

struct SubscriptionObject {
    // The publisher's slot: the object array never moves, and the
    // incarnation below tells whether the slot still holds that publisher.
    PublisherObject* publisher = nullptr;
    uint32_t incarnation = 0; ///< The publisher slot's incarnation when it was opened.
};

// What a waiting reader asked for and, once woken with Ok, received.
struct ReadRequest {
    DsmPage* page;
    uint32_t blockedAt; ///< The publisher's data identifier when the reader began to wait.
    uint32_t dataId;    ///< The identifier of the page handed over.
};

ObjectTable<PublisherObject*, kPublisherCapacity, TaskOwnerKeys> publisherTable(ObjectType::DsmPublisher, 0);
PublisherObject publishers[kPublisherCapacity];
ObjectTable<SubscriptionObject, kSubscriptionCapacity, TaskOwnerKeys> subscriptionTable(ObjectType::DsmSubscription, 0);
bool started = false;

// Another node's publisher that subscriptions of this node's tasks read.
struct RemotePublisher {
    PublisherObject publisher;  // Its id is the remote publisher's; it is in no table.
    uint16_t subscriptions = 0; // Open through it; the slot is free at 0.
    bool withdrawn = false;     // Its node deleted it: its subscriptions read Deleted.
    PublicationFilter filter;
    PublicationAssembler assemblers[kNetworkInterfaces];
};

RemotePublisher remotePublishers[kRemotePublishers];
DsmNetworkStatistics networkCounters;

size_t publisherSlotOf(ObjectId id) { return publisherTable.slotNumber(id); }

// Activates the boot-time slots and takes the board's node id on the first
// call to the agent. Interrupts are disabled by the caller.
void start()
{
    if (!started) {
        // Cannot fail: the tables are empty and KernelConfig proves the boot counts fit.
        (void)publisherTable.setNode(localNode());
        (void)publisherTable.AddObjects(kPublishersActiveAtBoot);
        (void)subscriptionTable.setNode(localNode());
        (void)subscriptionTable.AddObjects(kSubscriptionsActiveAtBoot);
        started = true;
    }
}

Result<PublisherObject*> resolvePublisher(ObjectId id)
{
    // The table gives InvalidId, WrongType, Remote and StaleId.
    start();
    const Result<PublisherObject**> entry = publisherTable.resolve(id);
    if (!entry.ok()) {
        return entry.status();
    }
    if (((*entry.value())->slowWrite & kDying) != 0) {
        return Status::StaleId;
    }
    return *entry.value();
}

Result<SubscriptionObject*> resolveSubscription(ObjectId id)
{
    start();
    return subscriptionTable.resolve(id);
}

// A subscription the calling task owns (Close and Read): only its owner
// closes it or reads through it.
Result<SubscriptionObject*> resolveOwnSubscription(ObjectId id)
{
    const Result<SubscriptionObject*> subscription = resolveSubscription(id);
    if (!subscription.ok()) {
        return subscription.status();
    }
    const Status owner = subscriptionTable.checkOwner(id, currentTaskId());
    if (owner != Status::Ok) {
        return owner;
    }
    return subscription.value();
}

// Invalidates every subscription, wakes the waiting readers with Deleted
// and frees the slot. O(1) plus O(1) per waiting reader.
//
// A woken reader more urgent than the caller runs at once, in the middle of
// this function, and may call the agent again. Its subscription is
// therefore invalid and the publisher marked dying before the first wake,
// so it cannot wait again or open a new subscription, and the slot is
// freed last, so no new publisher can take it while waking is under way.
//
// A networked publisher's subscribers on other nodes are told with a
// withdrawal, sent here with interrupts still disabled (recovery walks the
// table under its guard); the link only queues it.
void destroy(PublisherObject& publisher, ObjectId id)
{
    const bool networked = (publisher.slowWrite & kNetworked) != 0;
    publisher.slowWrite = kDying;
    publisher.incarnation = publisher.incarnation + 1;
    TaskManager::wakeAll(publisher.readers, Status::Deleted);
    publisher.dataId = kNoDsmData;
    publisher.page = DsmPage{};
    publisher.id = ObjectId::null();
    publisher.publishPending = false;
    publisher.slowWrite = 0;
    (void)publisherTable.Delete(id);
    if (networked) {
        sendWithdrawal(id, publisher.visibility, publisher.priority);
    }
}

// The remote publisher @p subscription reads, or null for a local one.
RemotePublisher* remoteOf(const SubscriptionObject& subscription)
{
    const auto* first = &remotePublishers[0].publisher;
    const auto* last = &remotePublishers[kRemotePublishers - 1].publisher;
    if (subscription.publisher < first || subscription.publisher > last) {
        return nullptr;
    }
    for (RemotePublisher& remote : remotePublishers) {
        if (&remote.publisher == subscription.publisher) {
            return &remote;
        }
    }
    return nullptr;
}

// A subscription is going: the remote publisher it read loses one, and is
// free again when it has none left. Under the guard.
void releaseRemote(const SubscriptionObject& subscription)
{
    RemotePublisher* const remote = remoteOf(subscription);
    if (remote == nullptr || remote->subscriptions == 0) {
        return;
    }
    if (--remote->subscriptions == 0) {
        remote->publisher.id = ObjectId::null();
        remote->publisher.incarnation = remote->publisher.incarnation + 1;
    }
}

// The live remote publisher for @p id, or null. O(kRemotePublishers), under the guard.
RemotePublisher* findRemote(ObjectId id)
{
    for (RemotePublisher& remote : remotePublishers) {
        if (remote.subscriptions != 0 && !remote.withdrawn && remote.publisher.id == id) {
            return &remote;
        }
    }
    return nullptr;
}

unsigned recoverDsm(ObjectId deadTask)
{
    arch_x86::InterruptGuard guard;
    start();
    const size_t publishersRecovered = publisherTable.forEachOwnedBy(
        deadTask, [](ObjectId id, PublisherObject*& publisher) { destroy(*publisher, id); });
    const size_t subscriptionsRecovered =
        subscriptionTable.forEachOwnedBy(deadTask, [](ObjectId id, SubscriptionObject& subscription) {
            releaseRemote(subscription);
            (void)subscriptionTable.Delete(id);
        });
    return static_cast<unsigned>(publishersRecovered + subscriptionsRecovered);
}

// What goes out on the links for one publication of a publisher, copied
// under the guard so that it is sent with interrupts enabled.
struct Outgoing {
    ObjectId id;
    uint32_t dataId = kNoDsmData;
    DsmPage page{};
    Visibility visibility = Visibility::Local;
    uint8_t priority = 0;
};

// @p publisher's latest page as a publication, at the priority of its last
// writing task. Under the guard.
Outgoing outgoingOf(const PublisherObject& publisher)
{
    Outgoing out;
    out.id = publisher.id;
    out.dataId = publisher.dataId;
    copySixteenBytes(out.page.bytes, publisher.page.bytes);
    out.visibility = publisher.visibility;
    out.priority = publisher.priority;
    return out;
}

void send(const Outgoing& out) { sendPublication(out.id, out.visibility, out.dataId, out.page, out.priority); }

// Takes @p page into @p publisher with the next data identifier, which it
// returns, and hands it to the waiting readers. Under the guard.
uint32_t publishLocally(PublisherObject& publisher, const DsmPage& page)
{
    copySixteenBytes(publisher.page.bytes, page.bytes);
    publisher.dataId = nextDataId(publisher.dataId);
    // Every reader that began to wait before this Write gets the page. A
    // woken reader more urgent than the writer runs at once, inside this
    // loop, and may Read again and wait again, or an interrupt handler may
    // Write again. Such a reader joins the queue behind those still to be
    // served (first come first served), having waited at the latest
    // identifier, and the loop stops at it: nobody is served twice with the
    // same page, and every reader gets the latest page at its hand-over.
    while (!publisher.readers.isEmpty()) {
        Task& reader = publisher.readers.first();
        ReadRequest& request = *reinterpret_cast<ReadRequest*>(reader.waitData);
        if (request.blockedAt == publisher.dataId) {
            break;
        }
        *request.page = publisher.page;
        request.dataId = publisher.dataId;
        TaskManager::wakeFirst(publisher.readers, Status::Ok);
    }
    return publisher.dataId;
}

// DsmAgent::Open for another node's publisher: a subscription to a remote
// publisher of this node, once the publisher's node has said it exists
// and may be read from here.
//
// Only a publisher's id reaches here: the table's miss path says WrongType
// for any other type before it says Remote.
Result<ObjectId> openRemote(ObjectId publisherId)
{
    // The subscription is made first, owned by the caller, so that a caller
    // killed while it waits for the publisher's node leaves nothing behind:
    // recovery closes it like any other. The remote publisher is taken
    // first too, so that the page the publisher's node sends again on
    // receiving the request finds it.
    ObjectId subscriptionId;
    {
        arch_x86::InterruptGuard guard;
        start();
        RemotePublisher* remote = findRemote(publisherId);
        if (remote == nullptr) {
            for (RemotePublisher& candidate : remotePublishers) {
                if (candidate.subscriptions == 0) {
                    remote = &candidate;
                    break;
                }
            }
            if (remote == nullptr) {
                ++networkCounters.noRemotePublisher;
                return Status::TableFull;
            }
            remote->publisher.id = publisherId;
            remote->publisher.dataId = kNoDsmData;
            remote->publisher.page = DsmPage{};
            remote->withdrawn = false;
            remote->filter.reset();
            for (PublicationAssembler& assembler : remote->assemblers) {
                assembler.reset();
            }
        }
        const Result<ObjectId> id = subscriptionTable.Create(currentTaskId(), nullptr, Visibility::Local);
        if (!id.ok()) {
            return id.status();
        }
        subscriptionId = id.value();
        ++remote->subscriptions;
        *subscriptionTable.resolve(subscriptionId).value() =
            SubscriptionObject{&remote->publisher, remote->publisher.incarnation};
    }
    const Result<uint32_t> opened = forwardRemote(RemoteService::DsmOpen, publisherId, 0);
    if (opened.ok()) {
        return subscriptionId;
    }
    arch_x86::InterruptGuard guard;
    const Result<SubscriptionObject*> subscription = resolveSubscription(subscriptionId);
    if (subscription.ok()) {
        releaseRemote(*subscription.value());
        (void)subscriptionTable.Delete(subscriptionId);
    }
    return opened.status();
}

} // namespace


size_t DsmManager::publisherCount()
{
    arch_x86::InterruptGuard guard;
    start();
    return publisherTable.usedCount();
}

size_t DsmManager::subscriptionCount()
{
    arch_x86::InterruptGuard guard;
    start();
    return subscriptionTable.usedCount();
}

void DsmManager::deliverPublication(uint8_t interface, uint16_t node, const PublicationPart& part, uint64_t nowNs)
{
    arch_x86::InterruptGuard guard;
    start();
    RemotePublisher* const remote = findRemote(publisherOn(node, part.index));
    if (remote == nullptr || interface >= kNetworkInterfaces) {
        ++networkCounters.unsubscribed; // Nobody here reads it: the common case of a broadcast.
        return;
    }
    if (part.kind == PublicationPartKind::Withdrawal) {
        ++networkCounters.withdrawals;
        remote->withdrawn = true;
        remote->publisher.incarnation = remote->publisher.incarnation + 1;
        TaskManager::wakeAll(remote->publisher.readers, Status::Deleted);
        return;
    }
    PublicationAssembler& assembler = remote->assemblers[interface];
    switch (assembler.take(part)) {
    case PublicationAssembler::Outcome::Gathering: return;
    case PublicationAssembler::Outcome::Dropped: ++networkCounters.torn; return;
    case PublicationAssembler::Outcome::Complete: break;
    }
    if (!remote->filter.take(assembler.sequence(), nowNs)) {
        ++networkCounters.duplicates;
        return;
    }
    ++networkCounters.received;
    (void)publishLocally(remote->publisher, assembler.page());
}

Result<uint32_t> DsmManager::serveRemoteOpen(ObjectId publisherId, bool withinController)
{
    Outgoing out;
    {
        arch_x86::InterruptGuard guard;
        start();
        const Result<PublisherObject*> publisher = resolvePublisher(publisherId);
        if (!publisher.ok()) {
            return publisher.status();
        }
        // Visibility (seed 6.4): a local publisher is this node's alone, a
        // regional one the controller's.
        const Visibility visibility = publisher.value()->visibility;
        if (visibility == Visibility::Local || (visibility == Visibility::Regional && !withinController)) {
            return Status::NotPermitted;
        }
        out = outgoingOf(*publisher.value());
    }
    if (out.dataId != kNoDsmData) {
        // The new subscriber's node has the latest page at once, not at the
        // next Write, at the requester's priority; the others drop it as a
        // duplicate.
        out.priority = Scheduler::current().priority;
        send(out);
    }
    return out.dataId;
}

void DsmManager::publishDeferred()
{
    // O(publishers): only an interrupt handler's Write asks for this.
    for (PublisherObject& publisher : publishers) {
        Outgoing out;
        {
            arch_x86::InterruptGuard guard;
            if (!publisher.publishPending) {
                continue;
            }
            publisher.publishPending = false;
            out = outgoingOf(publisher);
        }
        send(out);
    }
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> DsmManager::publisherNameToObject(const char* name, Visibility askingScope)
{
    arch_x86::InterruptGuard guard;
    start();
    return publisherTable.NameToObject(name, askingScope);
}

DsmNetworkStatistics DsmManager::networkStatistics()
{
    arch_x86::InterruptGuard guard;
    return internal::networkCounters;
}

RemotePublisherInfo DsmManager::remotePublisher(size_t slot)
{
    RemotePublisherInfo info;
    if (slot >= kRemotePublishers) {
        return info;
    }
    arch_x86::InterruptGuard guard;
    const RemotePublisher& remote = remotePublishers[slot];
    info.inUse = remote.subscriptions != 0;
    info.publisher = remote.publisher.id;
    info.subscriptions = remote.subscriptions;
    info.withdrawn = remote.withdrawn;
    info.dataId = remote.publisher.dataId;
    return info;
}

DCOS_RESOURCE_RECOVERY(dsmRecovery, "distributed shared memory", recoverDsm);

ObjectTableView publisherTableView()
{
    return publisherTable.view();
}

} // namespace dcos::internal

namespace dcos {

using internal::PublisherObject;
using internal::publisherTable;
using internal::ReadRequest;
using internal::resolvePublisher;
using internal::resolveSubscription;
using internal::start;
using internal::SubscriptionObject;
using internal::subscriptionTable;
using internal::TaskManager;

DCOS_CONFIGURATION_SERVICE Result<ObjectId> DsmAgent::Create(const char* name, Visibility visibility)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt; // The publisher would belong to whichever task was interrupted.
    }
    arch_x86::InterruptGuard guard;
    start();
    const Result<ObjectId> id = publisherTable.Create(internal::currentTaskId(), name, visibility);
    if (!id.ok()) {
        return id.status();
    }
    PublisherObject& publisher = internal::publishers[internal::publisherSlotOf(id.value())];
    publisher.id = id.value();
    publisher.dataId = kNoDsmData;
    publisher.page = DsmPage{};
    publisher.visibility = visibility;
    publisher.slowWrite = visibility == Visibility::Global ? internal::kNetworked : 0;
    publisher.publishPending = false;
    publisher.priority = internal::Scheduler::started() ? internal::Scheduler::current().priority : 0;
    *publisherTable.resolve(id.value()).value() = &publisher;
    return id.value();
}

DCOS_CONFIGURATION_SERVICE Status DsmAgent::Delete(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    start();
    const Result<PublisherObject*> publisher = resolvePublisher(id);
    if (!publisher.ok()) {
        return publisher.status();
    }
    const Status owner =
        publisherTable.checkOwnerOrPrivileged(id, internal::currentTaskId(), internal::currentTaskIsSuperUser());
    if (owner != Status::Ok) {
        return owner;
    }
    internal::destroy(*publisher.value(), id);
    return Status::Ok;
}

namespace {


// The complete Write: every case, from the id. DsmAgent::Write's fast path
// comes here for all it does not handle. A networked publisher's page goes
// out on the links after the local hand-over, with interrupts enabled.
[[gnu::noinline]] Result<uint32_t> writeFull(ObjectId id, const DsmPage* newPage)
{
    internal::Outgoing out;
    {
        arch_x86::InterruptGuard guard;
        start();
        const Result<PublisherObject*> resolved = resolvePublisher(id);
        if (!resolved.ok()) {
            return resolved.status();
        }
        const bool interrupt = internal::inInterruptContext();
        if (!interrupt) {
            const Status ownerCheck = publisherTable.checkOwner(id, internal::currentTaskId());
            if (ownerCheck != Status::Ok) {
                return ownerCheck; // Single writer: the owner, super user or not.
            }
        }
        PublisherObject& publisher = *resolved.value();
        const uint32_t written = internal::publishLocally(publisher, *newPage);
        if ((publisher.slowWrite & internal::kNetworked) == 0) {
            return written;
        }
        if (interrupt) {
            // A handler cannot use a driver: the network receiver task
            // publishes the page, the latest one when it comes to it.
            publisher.publishPending = true;
            ++internal::networkCounters.deferred;
            internal::requestDeferredPublications();
            return written;
        }
        publisher.priority = internal::Scheduler::current().priority;
        out = internal::outgoingOf(publisher);
    }
    internal::send(out);
    return out.dataId;
}

} // namespace

Result<uint32_t> DsmAgent::Write(ObjectId id, const DsmPage& page)
{
    // The fast path: the table's inline lookup, with the owner, for a live
    // publisher written by its owner (or by an interrupt handler) with no
    // reader waiting. A hand-over to waiting readers, an error or a wrong
    // id goes the full way.
    {
        arch_x86::InterruptGuard guard;
        ObjectId owner;
        PublisherObject* const* found = publisherTable.find(id, owner);
        if (found != nullptr) [[likely]] {
            PublisherObject& publisher = **found;
            // The owner's test comes before the interrupt context's: a
            // handler may write whoever owns the publisher, so the order
            // changes no outcome, and the common writer, the owner, skips
            // the nesting depth's load and test.
            if (publisher.slowWrite == 0 && publisher.readers.isEmpty()
                && ((internal::Scheduler::started() && owner == internal::Scheduler::current().id)
                    || internal::inInterruptContext())) [[likely]] {
                internal::copySixteenBytes(publisher.page.bytes, page.bytes);
                const uint32_t written = internal::nextDataId(publisher.dataId);
                publisher.dataId = written;
                return written;
            }
        }
    }
    return writeFull(id, &page);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> DsmAgent::Open(ObjectId publisherId)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    {
        arch_x86::InterruptGuard guard;
        start();
        const Result<PublisherObject*> publisher = resolvePublisher(publisherId);
        if (publisher.status() != Status::Remote) {
            if (!publisher.ok()) {
                return publisher.status();
            }
            const Result<ObjectId> id =
                subscriptionTable.Create(internal::currentTaskId(), nullptr, Visibility::Local);
            if (!id.ok()) {
                return id.status();
            }
            *subscriptionTable.resolve(id.value()).value() =
                SubscriptionObject{publisher.value(), publisher.value()->incarnation};
            return id.value();
        }
    }
    // Another node's publisher: asked for over the network, so with
    // interrupts enabled.
    return internal::openRemote(publisherId);
}

DCOS_CONFIGURATION_SERVICE Status DsmAgent::Close(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    const Result<SubscriptionObject*> subscription = internal::resolveOwnSubscription(id);
    if (!subscription.ok()) {
        return subscription.status();
    }
    internal::releaseRemote(*subscription.value());
    return subscriptionTable.Delete(id);
}

namespace {

// What Read does with a resolved subscription of the caller, under the
// caller's interrupt guard: no newer data yet (the fast path's miss), a
// deleted publisher, or a wait.
//
// The time-out comes by reference: passed by value, its two words are
// loaded and spilled in the fast path's prologue, whether or not it calls.
[[gnu::noinline]] Result<uint32_t> readResolved(const SubscriptionObject& subscription, uint32_t lastSeenDataId,
                                                DsmPage& page, const uint64_t& timeoutNs)
{
    PublisherObject& publisher = *subscription.publisher;
    if (publisher.incarnation != subscription.incarnation) {
        return Status::Deleted;
    }
    if (publisher.dataId != kNoDsmData && publisher.dataId != lastSeenDataId) {
        internal::copySixteenBytes(page.bytes, publisher.page.bytes);
        return publisher.dataId;
    }
    if (timeoutNs == kPoll) {
        return Status::WouldBlock;
    }
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    ReadRequest request{&page, publisher.dataId, kNoDsmData};
    internal::Scheduler::current().waitData = reinterpret_cast<uintptr_t>(&request);
    const Status woken = TaskManager::blockOn(publisher.readers, timeoutNs);
    if (woken != Status::Ok) {
        return woken;
    }
    return request.dataId;
}

// The complete Read from the id, for the ids the fast path's lookup refuses.
[[gnu::noinline]] Result<uint32_t> readFull(ObjectId id, uint32_t lastSeenDataId, DsmPage* page,
                                            const uint64_t& timeoutNs)
{
    arch_x86::InterruptGuard guard;
    const Result<SubscriptionObject*> resolved = internal::resolveOwnSubscription(id);
    if (!resolved.ok()) {
        return resolved.status();
    }
    return readResolved(*resolved.value(), lastSeenDataId, *page, timeoutNs);
}

} // namespace

Result<uint32_t> DsmAgent::Read(ObjectId id, uint32_t lastSeenDataId, DsmPage& page, uint64_t timeoutNs)
{
    // The fast path: the table's inline lookup, with the owner, for the
    // subscription's owner, when the publisher holds data newer than
    // lastSeenDataId. A wait, an error or a wrong id goes the full way.
    {
        arch_x86::InterruptGuard guard;
        ObjectId owner;
        const SubscriptionObject* subscription = subscriptionTable.find(id, owner);
        if (subscription != nullptr && internal::Scheduler::started() && owner == internal::Scheduler::current().id)
            [[likely]] {
            const PublisherObject& publisher = *subscription->publisher;
            const uint32_t dataId = publisher.dataId;
            if (publisher.incarnation == subscription->incarnation && dataId != kNoDsmData && dataId != lastSeenDataId)
                [[likely]] {
                internal::copySixteenBytes(page.bytes, publisher.page.bytes);
                return dataId;
            }
            return readResolved(*subscription, lastSeenDataId, page, timeoutNs);
        }
    }
    return readFull(id, lastSeenDataId, &page, timeoutNs);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> DsmAgent::NameToObject(const char* name)
{
    return internal::orRemoteName(internal::DsmManager::publisherNameToObject(name, Visibility::Local),
                                  ObjectType::DsmPublisher, name);
}

DCOS_CONFIGURATION_SERVICE Status DsmAgent::AddObjects(size_t count)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    start();
    return publisherTable.AddObjects(count);
}

DCOS_CONFIGURATION_SERVICE Status DsmAgent::AddSubscribers(size_t count)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    start();
    return subscriptionTable.AddObjects(count);
}

DCOS_CONFIGURATION_SERVICE Status DsmAgent::XferOwnership(ObjectId id, ObjectId newOwner)
{
    const Status newOwnerStatus = TaskManager::checkNewOwner(newOwner);
    if (newOwnerStatus != Status::Ok) {
        return newOwnerStatus;
    }
    arch_x86::InterruptGuard guard;
    start();
    const ObjectId caller = internal::currentTaskId();
    if (id.type() == ObjectType::DsmSubscription) {
        const Result<SubscriptionObject*> subscription = resolveSubscription(id);
        return subscription.ok() ? subscriptionTable.XferOwnership(id, caller, newOwner) : subscription.status();
    }
    const Result<PublisherObject*> publisher = resolvePublisher(id);
    return publisher.ok() ? publisherTable.XferOwnership(id, caller, newOwner) : publisher.status();
}

} // namespace dcos
