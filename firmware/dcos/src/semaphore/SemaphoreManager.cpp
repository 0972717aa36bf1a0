// The semaphore agent (seed 7.11): binary and counting semaphores with
// optional priority inheritance on binary ones.
//
// Priority inheritance: a binary semaphore with inheritance is an
// InheritanceSource. Its holder keeps every such semaphore it holds in a
// list, and runs at the most urgent priority among the first waiters of all
// of them (TaskManager::recomputePriority). Whenever that set of waiters
// changes (a task starts waiting, times out, is killed or changes priority,
// the semaphore is released or deleted) the holder is recomputed, so it
// drops back only as it releases the semaphores that lent it priority.
#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/internal/SemaphoreManager.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/FastPath.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/ObjectTable.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/ResourceRecovery.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/IdText.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <arch_x86/Cpu.hpp>
#include <boot/Panic.hpp>
#include <bsp/Board.hpp>
#include <shell/Shell.hpp>

#include <new>

namespace dcos {

namespace internal {

namespace {

struct Semaphore : InheritanceSource {
    Semaphore() : InheritanceSource(WaitQueue::Order::Priority) {}
    ObjectId id;
    SemaphoreKind kind = SemaphoreKind::Binary;
    uint32_t count = 0;
    uint32_t maximum = 1;
    bool inheritance = false;
    // A binary semaphore without priority inheritance: the one kind whose
    // Acquire and Release fast paths need no more than the holder list.
    bool plainBinary = false;
    // InheritanceSource::holder is the holding task of a binary semaphore
    // of this node; remoteHolder the task of another node that holds it
    // (holder then null, count 0; SemaphoreManager.hpp).
    ObjectId remoteHolder;
};

ObjectTable<Semaphore*, kSemaphoreCapacity, TaskOwnerKeys> table(ObjectType::Semaphore, 0);
Semaphore semaphores[kSemaphoreCapacity];
bool tableReady = false;

size_t slotOf(ObjectId id) { return table.slotNumber(id); }

void ensureTable()
{
    if (!tableReady) {
        if (table.setNode(localNode()) != Status::Ok || table.AddObjects(kSemaphoresActiveAtBoot) != Status::Ok) {
            dcosPanic("cannot set up the semaphore table (node %u, %lu semaphores)",
                      static_cast<unsigned>(localNode()), static_cast<unsigned long>(kSemaphoresActiveAtBoot));
        }
        tableReady = true;
    }
}

Result<Semaphore*> resolve(ObjectId id)
{
    ensureTable();
    const Result<Semaphore**> entry = table.resolve(id);
    if (!entry.ok()) {
        return entry.status();
    }
    return *entry.value();
}

// A waiter left, or changed priority: the holder's inherited priority follows.
void onWaitersChanged(WaitQueue&, void* context)
{
    Semaphore& semaphore = *static_cast<Semaphore*>(context);
    if (semaphore.inheritance && semaphore.holder != nullptr) {
        TaskManager::recomputePriority(*semaphore.holder);
    }
}

// Every binary semaphore is listed with its holder (see InheritanceSource),
// so recovery finds what a dead task held without searching the table.
void takeHold(Semaphore& semaphore, Task& task)
{
    semaphore.holder = &task;
    task.heldSources.pushBack(semaphore);
    if (semaphore.inheritance) {
        TaskManager::recomputePriority(task);
    }
}

void dropHold(Semaphore& semaphore)
{
    Task* holder = semaphore.holder;
    semaphore.holder = nullptr;
    if (holder != nullptr) {
        holder->heldSources.remove(semaphore);
        if (semaphore.inheritance) {
            TaskManager::recomputePriority(*holder);
        }
    }
}

// Frees a semaphore's slot and wakes its waiters with why.
void destroy(Semaphore& semaphore, Status why)
{
    dropHold(semaphore);
    semaphore.remoteHolder = ObjectId::null();
    semaphore.waiters.setObserver(nullptr, nullptr);
    TaskManager::wakeAll(semaphore.waiters, why);
    (void)table.Delete(semaphore.id); // Cannot fail: the callers resolved the id under the same lock.
}

// Gives up a remote holder's hold that will never be released (the holder
// ended, or its node started again): the semaphore is free, and its
// waiters learn the holder ended, as when a local holder dies.
void abandonRemoteHold(Semaphore& semaphore)
{
    semaphore.remoteHolder = ObjectId::null();
    semaphore.count = 1;
    TaskManager::wakeAll(semaphore.waiters, Status::Abandoned);
}

unsigned recoverSemaphores(ObjectId deadTask)
{
    arch_x86::InterruptGuard guard;
    if (!tableReady) {
        return 0;
    }
    unsigned recovered = 0;
    // Semaphores the dead task held: free them and tell every waiter that
    // the holder is gone. O(semaphores held), from the holder's own list.
    const Result<Task*> dead = TaskManager::resolve(deadTask);
    if (dead.ok()) {
        while (!dead.value()->heldSources.isEmpty()) {
            Semaphore& semaphore = static_cast<Semaphore&>(dead.value()->heldSources.front());
            dropHold(semaphore);
            semaphore.count = 1;
            TaskManager::wakeAll(semaphore.waiters, Status::Abandoned);
            ++recovered;
        }
    }
    // Semaphores it created.
    recovered += static_cast<unsigned>(table.forEachOwnedBy(deadTask, [](ObjectId, Semaphore*& semaphore) {
        destroy(*semaphore, Status::Deleted);
    }));
    return recovered;
}

} // namespace

DCOS_RESOURCE_RECOVERY(semaphoreRecovery, "semaphore", recoverSemaphores);

size_t semaphoreCount()
{
    arch_x86::InterruptGuard guard;
    ensureTable();
    return table.usedCount();
}

Result<bool> isBinarySemaphore(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> semaphore = resolve(id);
    if (!semaphore.ok()) {
        return semaphore.status();
    }
    return semaphore.value()->kind == SemaphoreKind::Binary;
}

Result<uint32_t> semaphoreSettings(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> semaphore = resolve(id);
    if (!semaphore.ok()) {
        return semaphore.status();
    }
    const Semaphore& s = *semaphore.value();
    return (s.kind == SemaphoreKind::Counting ? 1u : 0u) | (s.inheritance ? 2u : 0u) |
           (s.waiters.order() == WaitQueue::Order::Fifo ? 4u : 0u);
}

ObjectId remoteHolderOf(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> semaphore = resolve(id);
    return semaphore.ok() ? semaphore.value()->remoteHolder : ObjectId::null();
}

Status holdForRemote(ObjectId id, ObjectId holder)
{
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> resolved = resolve(id);
    if (!resolved.ok()) {
        return resolved.status();
    }
    Semaphore& semaphore = *resolved.value();
    if (semaphore.kind != SemaphoreKind::Binary || inInterruptContext() ||
        semaphore.holder != &Scheduler::current()) {
        return Status::NotOwner;
    }
    dropHold(semaphore);
    semaphore.remoteHolder = holder;
    return Status::Ok;
}

Status releaseForRemote(ObjectId id, ObjectId holder)
{
    {
        arch_x86::InterruptGuard guard;
        const Result<Semaphore*> resolved = resolve(id);
        if (!resolved.ok()) {
            return resolved.status();
        }
        Semaphore& semaphore = *resolved.value();
        if (semaphore.kind == SemaphoreKind::Binary) {
            if (semaphore.remoteHolder.isNull() || semaphore.remoteHolder != holder) {
                return Status::NotOwner;
            }
            semaphore.remoteHolder = ObjectId::null();
            if (semaphore.waiters.isEmpty()) {
                semaphore.count = 1;
                return Status::Ok;
            }
            // Handed straight to the first waiter, as a local Release does.
            Task& next = semaphore.waiters.first();
            semaphore.waiters.remove(next);
            next.waitingOn = nullptr;
            takeHold(semaphore, next);
            TaskManager::wake(next, Status::Ok);
            return Status::Ok;
        }
    }
    return SemaphoreAgent::Release(id);
}

namespace {

// Whether a remote GetState of a holder says it is gone: it ended (its id
// names no task any more), or its node does not answer.
bool holderGone(ObjectId holder)
{
    const Result<TaskState> state = TaskAgent::GetState(holder);
    if (state.ok()) {
        return state.value() == TaskState::NonExistent || state.value() == TaskState::Terminating;
    }
    return state.status() == Status::InvalidId || state.status() == Status::StaleId ||
           state.status() == Status::Unreachable;
}

} // namespace

bool probeRemoteHolder(ObjectId id)
{
    const ObjectId holder = remoteHolderOf(id);
    if (holder.isNull() || !holderGone(holder)) {
        return false;
    }
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> resolved = resolve(id);
    // Asked with interrupts enabled: the holder may have released it meanwhile.
    if (!resolved.ok() || resolved.value()->remoteHolder != holder) {
        return false;
    }
    abandonRemoteHold(*resolved.value());
    return true;
}

size_t freeHoldsOfNode(uint16_t node)
{
    ensureTable();
    size_t freed = 0;
    for (size_t slot = 0; slot < table.activeCount(); ++slot) {
        arch_x86::InterruptGuard guard;
        Semaphore& semaphore = semaphores[slot];
        // A deleted semaphore's remote holder is null (destroy()).
        if (semaphore.remoteHolder.isNull() || semaphore.remoteHolder.node() != node) {
            continue;
        }
        abandonRemoteHold(semaphore);
        ++freed;
    }
    return freed;
}

// The complete Acquire and Release: every case, from a resolved id.
// The agent's fast paths (below) come here for all they do not handle.
// @p heldRemotely is set when the semaphore is held by another node's task:
// the wait then lasts one probe slice at most (SemaphoreManager.hpp).
[[gnu::always_inline]] inline Status acquireLocal(ObjectId id, const uint64_t* timeoutIn, bool& heldRemotely)
{
    uint64_t timeout = *timeoutIn;
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> resolved = resolve(id);
    if (!resolved.ok()) {
        return resolved.status();
    }
    Semaphore& semaphore = *resolved.value();
    const bool inInterrupt = inInterruptContext();
    if (semaphore.kind == SemaphoreKind::Binary) {
        if (semaphore.count == 1) {
            if (inInterrupt) {
                return Status::InInterrupt; // A handler cannot hold a semaphore.
            }
            semaphore.count = 0;
            takeHold(semaphore, Scheduler::current());
            return Status::Ok;
        }
        if (!inInterrupt && semaphore.holder == &Scheduler::current()) {
            return Status::Deadlock;
        }
    } else if (semaphore.count > 0) {
        semaphore.count = semaphore.count - 1;
        return Status::Ok;
    }
    if (timeout == kPoll) {
        return Status::WouldBlock;
    }
    if (inInterrupt) {
        return Status::InInterrupt;
    }
    if (!semaphore.remoteHolder.isNull()) [[unlikely]] {
        heldRemotely = true;
        timeout = timeout < kHolderProbeNs ? timeout : kHolderProbeNs;
    }
    Task& self = Scheduler::current();
    // The unit is handed over by Release, so success needs no retry.
    semaphore.waiters.add(self);
    self.waitingOn = &semaphore.waiters;
    if (semaphore.inheritance && semaphore.holder != nullptr) {
        TaskManager::recomputePriority(*semaphore.holder);
    }
    return TaskManager::blockCurrent(WaitReason::Object, timeout);
}

[[gnu::always_inline]] inline Status releaseLocal(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> resolved = resolve(id);
    if (!resolved.ok()) {
        return resolved.status();
    }
    Semaphore& semaphore = *resolved.value();
    if (semaphore.kind == SemaphoreKind::Binary) {
        if (inInterruptContext() || semaphore.holder != &Scheduler::current()) {
            return Status::NotOwner;
        }
        Task& self = Scheduler::current();
        if (semaphore.waiters.isEmpty()) {
            dropHold(semaphore);
            semaphore.count = 1;
            return Status::Ok;
        }
        // Hand the semaphore straight to the first waiter, so no other task
        // can slip in between and the waiter's wait always succeeds. The
        // waiter is readied before this task drops back from the priority
        // it inherited: dropping first would let a task of middling
        // priority run before the waiter (the very inversion inheritance
        // exists to prevent).
        self.heldSources.remove(semaphore);
        semaphore.holder = nullptr;
        Task& next = semaphore.waiters.first();
        semaphore.waiters.remove(next);
        next.waitingOn = nullptr;
        takeHold(semaphore, next);
        TaskManager::wake(next, Status::Ok);
        if (semaphore.inheritance) {
            TaskManager::recomputePriority(self);
        }
        return Status::Ok;
    }
    if (!semaphore.waiters.isEmpty()) {
        TaskManager::wakeFirst(semaphore.waiters, Status::Ok);
        return Status::Ok;
    }
    if (semaphore.count == semaphore.maximum) {
        return Status::InvalidArgument; // The count would exceed its maximum.
    }
    semaphore.count = semaphore.count + 1;
    return Status::Ok;
}

// The slow paths: the local cases, then, for another node's id, the remote
// transaction, with interrupts enabled again (it blocks).
// The rest of a wait for a binary semaphore held by another node's task,
// after its first slice ended with @p first: slices of kHolderProbeNs, the
// holder probed between them, so a holder that died does not keep the
// semaphore for ever. Apart from acquireFull, whose common path it would
// otherwise slow.
[[gnu::noinline]] Status acquireFromRemoteHolder(ObjectId id, uint64_t timeout, Status first)
{
    const bool forever = timeout == kWaitForever;
    uint64_t left = forever ? 0 : timeout - (timeout < kHolderProbeNs ? timeout : kHolderProbeNs);
    for (Status status = first;; ) {
        if (status != Status::Timeout) {
            return status;
        }
        if (!forever && left == 0) {
            return Status::Timeout;
        }
        if (probeRemoteHolder(id)) {
            return Status::Abandoned;
        }
        uint64_t slice = forever || left > kHolderProbeNs ? kHolderProbeNs : left;
        left -= forever ? 0 : slice;
        bool heldRemotely = false;
        status = acquireLocal(id, &slice, heldRemotely);
    }
}

[[gnu::noinline]] Status acquireFull(ObjectId id, const SpilledTimeout* spilled)
{
    const uint64_t timeout = spilled->value();
    bool heldRemotely = false;
    const Status status = acquireLocal(id, &timeout, heldRemotely);
    if (heldRemotely) [[unlikely]] {
        return acquireFromRemoteHolder(id, timeout, status);
    }
    return orRemote(status, RemoteService::SemaphoreAcquire, id, remoteTimeoutMs(timeout));
}

[[gnu::noinline]] Status releaseFull(ObjectId id) { return orRemote(releaseLocal(id), RemoteService::SemaphoreRelease, id, 0); }

ObjectTableView semaphoreTableView()
{
    return table.view();
}

} // namespace internal

using internal::Scheduler;
using internal::Semaphore;
using internal::Task;
using internal::TaskManager;

DCOS_CONFIGURATION_SERVICE Result<ObjectId> SemaphoreAgent::Create(const SemaphoreAttributes& attributes)
{
    const bool binary = attributes.kind == SemaphoreKind::Binary;
    if ((attributes.kind != SemaphoreKind::Binary && attributes.kind != SemaphoreKind::Counting) ||
        (binary && attributes.initialCount > 1) || (!binary && attributes.priorityInheritance) ||
        (!binary && (attributes.maximumCount == 0 || attributes.initialCount > attributes.maximumCount)) ||
        (attributes.order != WaitOrder::Priority && attributes.order != WaitOrder::Fifo)) {
        return Status::InvalidArgument;
    }
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    internal::ensureTable();
    const Result<ObjectId> id =
        internal::table.Create(internal::currentTaskId(), attributes.name, attributes.visibility);
    if (!id.ok()) {
        return id.status();
    }
    Semaphore& semaphore = internal::semaphores[internal::slotOf(id.value())];
    semaphore.~Semaphore();
    new (&semaphore) Semaphore();
    *internal::table.resolve(id.value()).value() = &semaphore;
    semaphore.id = id.value();
    semaphore.kind = attributes.kind;
    semaphore.count = attributes.initialCount;
    semaphore.maximum = binary ? 1 : attributes.maximumCount;
    semaphore.inheritance = attributes.priorityInheritance;
    semaphore.plainBinary = binary && !attributes.priorityInheritance;
    semaphore.lendsPriority = attributes.priorityInheritance;
    semaphore.waiters.setOrder(attributes.order == WaitOrder::Fifo ? internal::WaitQueue::Order::Fifo
                                                                   : internal::WaitQueue::Order::Priority);
    semaphore.waiters.setObserver(internal::onWaitersChanged, &semaphore);
    // A binary semaphore created taken is held by its creator.
    if (binary && attributes.initialCount == 0 && Scheduler::started()) {
        internal::takeHold(semaphore, Scheduler::current());
    }
    return semaphore.id;
}

DCOS_CONFIGURATION_SERVICE Status SemaphoreAgent::Delete(ObjectId id)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> semaphore = internal::resolve(id);
    if (!semaphore.ok()) {
        return semaphore.status();
    }
    const Status owner =
        internal::table.checkOwnerOrPrivileged(id, internal::currentTaskId(), internal::currentTaskIsSuperUser());
    if (owner != Status::Ok) {
        return owner;
    }
    internal::destroy(*semaphore.value(), Status::Deleted);
    return Status::Ok;
}

Status SemaphoreAgent::Acquire(ObjectId id, uint64_t timeout)
{
    // The fast path takes a free binary semaphore without inheritance from
    // a task, or a unit of a counting one; everything else, a wrong id and
    // a semaphore with inheritance included, goes the full way.
    {
        arch_x86::InterruptGuard guard;
        Semaphore* const* found = internal::table.find(id);
        if (found != nullptr) [[likely]] {
            Semaphore& semaphore = **found;
            if (semaphore.plainBinary) {
                if (semaphore.count == 1 && !internal::inInterruptContext()) {
                    Task& self = Scheduler::current();
                    semaphore.count = 0;
                    semaphore.holder = &self;
                    self.heldSources.pushBack(semaphore); // For recovery (see takeHold).
                    return Status::Ok;
                }
            } else if (semaphore.kind == SemaphoreKind::Counting && semaphore.count > 0) {
                semaphore.count = semaphore.count - 1;
                return Status::Ok;
            }
        }
    }
    const internal::SpilledTimeout spilled(timeout);
    return internal::callSlowPath(internal::acquireFull, id, &spilled);
}

Status SemaphoreAgent::Release(ObjectId id)
{
    // The fast path gives back what no task waits for; a hand-over to a
    // waiter, a semaphore with inheritance, an error or a wrong id goes the
    // full way.
    {
        arch_x86::InterruptGuard guard;
        Semaphore* const* found = internal::table.find(id);
        if (found != nullptr) [[likely]] {
            Semaphore& semaphore = **found;
            if (semaphore.waiters.isEmpty()) {
                if (semaphore.plainBinary) {
                    // The holder is the caller, so it is not null and the
                    // semaphore is on the caller's list (see dropHold).
                    if (semaphore.holder == &Scheduler::current() && !internal::inInterruptContext()) {
                        semaphore.holder = nullptr;
                        Scheduler::current().heldSources.remove(semaphore);
                        semaphore.count = 1;
                        return Status::Ok;
                    }
                } else if (semaphore.kind == SemaphoreKind::Counting && semaphore.count != semaphore.maximum) {
                    semaphore.count = semaphore.count + 1;
                    return Status::Ok;
                }
            }
        }
    }
    return internal::callSlowPath(internal::releaseFull, id);
}

Result<uint32_t> SemaphoreAgent::GetCount(ObjectId id)
{
    Status status;
    {
        arch_x86::InterruptGuard guard;
        const Result<Semaphore*> semaphore = internal::resolve(id);
        if (semaphore.ok()) {
            return semaphore.value()->count;
        }
        status = semaphore.status();
    }
    // Forwarded with interrupts enabled again: the remote agent blocks.
    return internal::remoteValueOr<uint32_t>(status, internal::RemoteService::SemaphoreGetCount, id);
}

Result<ObjectId> SemaphoreAgent::GetHolder(ObjectId id)
{
    Status status;
    {
        arch_x86::InterruptGuard guard;
        const Result<Semaphore*> semaphore = internal::resolve(id);
        if (semaphore.ok()) {
            return semaphore.value()->holder != nullptr ? semaphore.value()->holder->id
                                                        : semaphore.value()->remoteHolder;
        }
        status = semaphore.status();
    }
    return internal::remoteValueOr<ObjectId>(status, internal::RemoteService::SemaphoreGetHolder, id);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> SemaphoreAgent::NameToObject(const char* name)
{
    return internal::orRemoteName(internal::semaphoreNameToObject(name, Visibility::Local), ObjectType::Semaphore,
                                  name);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> internal::semaphoreNameToObject(const char* name, Visibility askingScope)
{
    arch_x86::InterruptGuard guard;
    internal::ensureTable();
    return internal::table.NameToObject(name, askingScope);
}

DCOS_CONFIGURATION_SERVICE Status SemaphoreAgent::XferOwnership(ObjectId id, ObjectId newOwner)
{
    arch_x86::InterruptGuard guard;
    const Result<Semaphore*> semaphore = internal::resolve(id);
    if (!semaphore.ok()) {
        return semaphore.status();
    }
    const Status newOwnerStatus = TaskManager::checkNewOwner(newOwner);
    if (newOwnerStatus != Status::Ok) {
        return newOwnerStatus;
    }
    const Status allowed = internal::table.checkOwnerOrPrivileged(id, internal::currentTaskId(),
                                                                   internal::currentTaskIsSuperUser());
    if (allowed != Status::Ok) {
        return allowed;
    }
    return internal::table.XferOwnership(id, internal::table.ownerOf(id).value(), newOwner);
}

DCOS_CONFIGURATION_SERVICE Status SemaphoreAgent::AddObjects(size_t count)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    internal::ensureTable();
    return internal::table.AddObjects(count);
}

namespace {

shell::CommandResult listSemaphores(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    shell.print("id           name             kind      count  holder       order     inherit\r\n");
    for (const Semaphore& s : internal::semaphores) {
        arch_x86::InterruptGuard guard;
        if (s.id.isNull() || !internal::table.resolve(s.id).ok()) {
            continue;
        }
        const Result<const char*> name = internal::table.nameOf(s.id);
        shell.print("%-10s   %-16s %-8s %6lu  %-10s   %-8s  %s\r\n", internal::IdText(s.id).c_str(),
                    name.ok() && name.value()[0] != '\0' ? name.value() : "-",
                    s.kind == SemaphoreKind::Binary ? "binary" : "counting", static_cast<unsigned long>(s.count),
                    internal::IdText(s.holder != nullptr ? s.holder->id : s.remoteHolder).c_str(),
                    s.waiters.order() == internal::WaitQueue::Order::Fifo ? "fifo" : "priority",
                    s.inheritance ? "yes" : "no");
    }
    shell.print("%lu semaphores\r\n", static_cast<unsigned long>(internal::semaphoreCount()));
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(semaphoresCommand, "semaphores", "list the semaphores", "semaphores",
                            "  id: the object id, 0x and eight hex digits in every listing and report; name: - when unnamed\r\n"
                            "  kind: binary or counting; count: units available now\r\n"
                            "  holder: the task holding a binary semaphore, - when free\r\n"
                            "  order: how waiters queue, fifo or priority; inherit: priority inheritance on",
                            listSemaphores);

} // namespace dcos
