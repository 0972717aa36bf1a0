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

#include <arch_x86/Cpu.hpp>

namespace dcos::internal {

namespace {

struct PublisherObject {
    ObjectId id;
    bool dying = false;       ///< Being deleted: refused as stale while its readers are woken.
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
    if ((*entry.value())->dying) {
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
void destroy(PublisherObject& publisher, ObjectId id)
{
    publisher.dying = true;
    publisher.incarnation = publisher.incarnation + 1;
    TaskManager::wakeAll(publisher.readers, Status::Deleted);
    publisher.dataId = kNoDsmData;
    publisher.page = DsmPage{};
    publisher.id = ObjectId::null();
    publisher.dying = false;
    (void)publisherTable.Delete(id);
}

unsigned recoverDsm(ObjectId deadTask)
{
    arch_x86::InterruptGuard guard;
    start();
    const size_t publishersRecovered = publisherTable.forEachOwnedBy(
        deadTask, [](ObjectId id, PublisherObject*& publisher) { destroy(*publisher, id); });
    const size_t subscriptionsRecovered = subscriptionTable.forEachOwnedBy(
        deadTask, [](ObjectId id, SubscriptionObject&) { (void)subscriptionTable.Delete(id); });
    return static_cast<unsigned>(publishersRecovered + subscriptionsRecovered);
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

DCOS_RESOURCE_RECOVERY(dsmRecovery, "distributed shared memory", recoverDsm);

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

// The next data identifier after @p dataId; kNoDsmData is skipped.
uint32_t nextDataId(uint32_t dataId) { return dataId + 1 == kNoDsmData ? dataId + 2 : dataId + 1; }

// The complete Write: every case, from the id. DsmAgent::Write's fast path
// comes here for all it does not handle.
[[gnu::noinline]] Result<uint32_t> writeFull(ObjectId id, const DsmPage* newPage)
{
    arch_x86::InterruptGuard guard;
    start();
    const Result<PublisherObject*> resolved = resolvePublisher(id);
    if (!resolved.ok()) {
        return resolved.status();
    }
    if (!internal::inInterruptContext()) {
        const Status ownerCheck = publisherTable.checkOwner(id, internal::currentTaskId());
        if (ownerCheck != Status::Ok) {
            return ownerCheck; // Single writer: the owner, super user or not.
        }
    }
    PublisherObject& publisher = *resolved.value();
    internal::copySixteenBytes(publisher.page.bytes, newPage->bytes);
    publisher.dataId = nextDataId(publisher.dataId);
    const uint32_t written = publisher.dataId;
    // Every reader that began to wait before this Write gets the page. A
    // woken reader more urgent than the writer runs at once, inside this
    // loop, and may Read again and wait again, or an interrupt handler may
    // Write again. Such a reader joins the queue behind those still to be
    // served (first come first served), having waited at the latest
    // identifier, and the loop stops at it: nobody is served twice with the
    // same page, and every reader gets the latest page at its hand-over.
    while (!publisher.readers.isEmpty()) {
        internal::Task& reader = publisher.readers.first();
        ReadRequest& request = *reinterpret_cast<ReadRequest*>(reader.waitData);
        if (request.blockedAt == publisher.dataId) {
            break;
        }
        *request.page = publisher.page;
        request.dataId = publisher.dataId;
        TaskManager::wakeFirst(publisher.readers, Status::Ok);
    }
    return written;
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
            if (!publisher.dying && publisher.readers.isEmpty()
                && (internal::inInterruptContext()
                    || (internal::Scheduler::started() && owner == internal::Scheduler::current().id))) [[likely]] {
                internal::copySixteenBytes(publisher.page.bytes, page.bytes);
                const uint32_t written = nextDataId(publisher.dataId);
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
    arch_x86::InterruptGuard guard;
    start();
    const Result<PublisherObject*> publisher = resolvePublisher(publisherId);
    if (!publisher.ok()) {
        return publisher.status();
    }
    const Result<ObjectId> id = subscriptionTable.Create(internal::currentTaskId(), nullptr, Visibility::Local);
    if (!id.ok()) {
        return id.status();
    }
    *subscriptionTable.resolve(id.value()).value() =
        SubscriptionObject{publisher.value(), publisher.value()->incarnation};
    return id.value();
}

DCOS_CONFIGURATION_SERVICE Status DsmAgent::Close(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    const Result<SubscriptionObject*> subscription = internal::resolveOwnSubscription(id);
    if (!subscription.ok()) {
        return subscription.status();
    }
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
    arch_x86::InterruptGuard guard;
    start();
    return publisherTable.NameToObject(name, Visibility::Local);
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
