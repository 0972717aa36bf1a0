// The buffer pool memory agent's kernel side (seed 7.7): the pool table,
// holders, serialisation and resource recovery around internal::BufferPool.
#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/internal/BufferPool.hpp>
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/HeapManager.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/MemoryAreaServices.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/ResourceRecovery.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos::internal {

namespace {

// Interrupt handlers may allocate and return buffers, so the agent's
// bookkeeping runs with interrupts disabled.
using Lock = arch_x86::InterruptGuard;

// A pool object: the algorithm's state and the pool's id, the null id
// while the slot is free. The fast paths find the object from the id without
// the table's entry (fastObjectOf()) and read nothing else of the slot, so
// what only Create reads (PoolArea) is kept apart and an object is 64 bytes.
struct PoolObject {
    BufferPool pool;
    ObjectId id;

    bool inUse() const { return !id.isNull(); }
};

#if !defined(DCOS_HOST_BUILD)
static_assert(sizeof(PoolObject) == 64, "a pool object holds what the fast paths read, and no more");
#endif

// The area reserved for the pool in the same slot, from the start of Create
// to Delete, including while Create lays out the buffers with interrupts
// enabled. Only Create's overlap check reads it, so it is kept apart from
// the objects the fast paths read.
struct PoolArea {
    uintptr_t begin = 0;
    uintptr_t end = 0;
};

using PoolTable = ObjectTable<PoolObject*, kPoolCapacity, TaskOwnerKeys>;

constinit PoolTable poolTable(ObjectType::BufferPool, 0);
constinit PoolObject pools[kPoolCapacity];
constinit PoolArea poolAreas[kPoolCapacity];
constinit bool started = false;
constinit uint32_t poolsCreated = 0;

size_t slotOf(ObjectId id) { return poolTable.slotNumber(id); }

// Where the pool object of each id index is, as a byte offset into pools:
// set by Create for the index its id got, so it is right for every live
// pool, and left as it is by Delete (the object it leads to is cleared, so
// it leads nowhere but to an object out of service). 0, pools[0], for an
// index never used. The table's own map (ObjectTable::slotNumber) holds
// slot numbers of 8 or 16 bits, which the i486 loads with a zero
// extension of two instructions and then scales; this one is a single load
// (4 bytes a possible index, 16 KiB, in .bss).
constinit uint32_t poolOffsets[ObjectId::kMaxIndex + 1];

// The fast paths' lookup: the object poolOffsets gives for @p id's index,
// which is the pool @p id names exactly when the object's whole id equals
// @p id (one compare checks node, type and index, as ObjectTable::find
// does). A free slot's object is all zero: it keeps the null id, which a
// null @p id does equal, but also a pool out of service (limit 0), whose
// fast paths decline every call, so the complete service gives InvalidId.
// Create sets the id and Delete clears the object under the lock, while
// the table's entry changes, so both always agree on which id is live.
[[gnu::always_inline]] inline PoolObject* fastObjectOf(ObjectId id)
{
    return reinterpret_cast<PoolObject*>(reinterpret_cast<uintptr_t>(pools) + poolOffsets[id.index()]);
}

// A buffer's handle on its holder's list (HeldList.hpp): the pool's slot in
// the high half, the buffer's index in the low one.
static_assert(kPoolCapacity <= 0x1000, "a pool's slot takes 12 bits of a handle, below the list marks");
[[gnu::always_inline]] inline uint32_t heldHandle(const PoolObject* object, uint32_t index)
{
    // The slot times 2^16, from the byte offset without a division where
    // the object's size is a power of two (64 bytes on the board).
    const uintptr_t offset = reinterpret_cast<uintptr_t>(object) - reinterpret_cast<uintptr_t>(pools);
    if constexpr ((sizeof(PoolObject) & (sizeof(PoolObject) - 1)) == 0 && sizeof(PoolObject) <= 0x10000) {
        return static_cast<uint32_t>(offset * (0x10000 / sizeof(PoolObject))) | index;
    } else {
        return static_cast<uint32_t>((offset / sizeof(PoolObject)) << 16) | index;
    }
}

// HeldList's resolver: the links of the buffer a handle names, or null when
// the slot's pool is not in service or the index is beyond its buffers. A
// mark (kHeldEnd and the others) has a slot above every capacity.
[[gnu::always_inline]] inline uint8_t* heldLinks(uint32_t handle)
{
    const uint32_t slot = handle >> 16;
    if (slot >= kPoolCapacity) [[unlikely]] {
        return nullptr;
    }
    return pools[slot].pool.linksIfInService(handle & 0xFFFF);
}

// The list operations with this agent's resolver, out of line for every
// path but the two fast ones, which inline their own.
[[gnu::noinline]] void takeHeld(HeldHead& head, uint32_t handle) { HeldList::take(head, handle, heldLinks); }

[[gnu::noinline]] void giveHeld(HeldHead& head, uint32_t handle, uint8_t* links)
{
    HeldList::give(head, handle, links, heldLinks);
}

constinit uint32_t recoveryWalkCount = 0;

// Gives back every buffer the dead task held, from its list; when the list
// was lost, from a walk over every pool for its holder tag.
size_t reclaimHeldBuffers(Task* task, uint16_t holder)
{
    return memory_area::reclaimHeld(
        task, &Task::heldBuffers, heldLinks,
        [holder](uint32_t handle) { return pools[handle >> 16].pool.reclaim(handle & 0xFFFF, holder); },
        [holder] {
            // Only active slots can hold an object: the walk is O(active slots), not O(capacity).
            size_t reclaimed = 0;
            const PoolObject* const activeEnd = pools + poolTable.activeCount();
            for (PoolObject* object = pools; object != activeEnd; ++object) {
                if (object->inUse() && object->pool.inService()) {
                    reclaimed += object->pool.reclaimHeldBy(holder);
                }
            }
            return reclaimed;
        },
        recoveryWalkCount);
}

// Activates the first slots on first use; call with interrupts disabled.
void start()
{
    if (!started) {
        (void)poolTable.AddObjects(kPoolsActiveAtBoot); // Cannot fail: checked by KernelConfig.hpp.
        started = true;
    }
    if (poolTable.usedCount() == 0 && poolTable.node() != localNode()) {
        (void)poolTable.setNode(localNode());
    }
}

// The id checks every primitive shares; call with interrupts disabled.
[[gnu::noinline]] Result<PoolObject*> resolveFully(ObjectId id)
{
    // The table gives InvalidId, WrongType, Remote (another node's object,
    // which Allocate and Return forward to the remote agent) and StaleId.
    start();
    const Result<PoolObject**> entry = poolTable.resolve(id);
    if (!entry.ok()) {
        return entry.status();
    }
    return *entry.value();
}

// Every service's lookup: the table's inline one, and on a miss the full
// resolve, which sets the tables up if need be and gives the reason.
[[gnu::always_inline]] inline Result<PoolObject*> lookup(ObjectId id)
{
    if (PoolObject* const* found = poolTable.find(id)) [[likely]] {
        return *found;
    }
    return resolveFully(id);
}

// Delete and XferOwnership of the pool need its owner or a super user.
Status checkOwnerOrSuperUser(ObjectId id)
{
    return poolTable.checkOwnerOrPrivileged(id, currentTaskId(), currentTaskIsSuperUser());
}

void remove(ObjectId id, PoolObject& object)
{
    (void)poolTable.Delete(id);
    poolAreas[&object - pools] = PoolArea{};
    object = PoolObject{};
}

unsigned recoverPools(ObjectId deadTask) { return BufferPoolManager::recoverResourcesOf(deadTask); }

} // namespace

DCOS_CONFIGURATION_SERVICE Result<ObjectId> BufferPoolManager::Create(void* area, size_t areaBytes, size_t bufferSize, const char* name,
                                           Visibility visibility)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    const uintptr_t begin = reinterpret_cast<uintptr_t>(area);
    if (area == nullptr || bufferSize < BufferPool::kMinimumBufferSize || areaBytes > UINTPTR_MAX - begin) {
        return Status::InvalidArgument;
    }
    const uintptr_t end = begin + areaBytes;

    // Reserve the slot and the area.
    ObjectId id;
    uint32_t salt;
    {
        Lock lock;
        start();
        if (overlapsArea(begin, end) || HeapManager::overlapsArea(begin, end)) {
            return Status::AlreadyExists;
        }
        const Result<ObjectId> created = poolTable.Create(currentTaskId(), name, visibility);
        if (!created.ok()) {
            return created.status();
        }
        id = created.value();
        PoolObject& object = pools[slotOf(id)];
        object = PoolObject{};
        object.id = id;
        poolAreas[slotOf(id)] = PoolArea{begin, end};
        poolOffsets[id.index()] = static_cast<uint32_t>(slotOf(id) * sizeof(PoolObject));
        *poolTable.resolve(id).value() = &object;
        ++poolsCreated;
        salt = mixBits(static_cast<uint32_t>(begin) ^ (poolsCreated * 0x9E3779B9u));
    }

    // Lay out the buffers, O(buffers), with interrupts enabled. Until the
    // pool is copied in below, the object reads as an empty pool.
    BufferPool laidOut;
    const Status layout = laidOut.initialise(area, areaBytes, bufferSize, salt);

    Lock lock;
    const Result<PoolObject*> object = lookup(id);
    if (!object.ok()) {
        return Status::Deleted; // A super user deleted the pool meanwhile.
    }
    if (layout != Status::Ok) {
        remove(id, *object.value());
        return layout;
    }
    object.value()->pool = laidOut;
    return id;
}

DCOS_CONFIGURATION_SERVICE Status BufferPoolManager::Delete(ObjectId id)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    Lock lock;
    const Result<PoolObject*> object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    const Status owner = checkOwnerOrSuperUser(id);
    if (owner != Status::Ok) {
        return owner;
    }
    const BufferPool& pool = object.value()->pool;
    if (!pool.isCorrupted() && pool.allocatedCount() != 0) {
        return Status::Busy;
    }
    remove(id, *object.value());
    return Status::Ok;
}

Result<void*> BufferPoolManager::Allocate(ObjectId id)
{
    Task* const task = memory_area::callerTask();
    const uint16_t holder = memory_area::holderOf(task, BufferPool::kSystemHolder);
    {
        Lock lock;
        const Result<PoolObject*> object = lookup(id);
        if (object.ok()) {
            BufferPool& pool = object.value()->pool;
            const Result<void*> buffer = pool.allocate(holder);
            if (buffer.ok()) {
                const uint32_t index = pool.indexOfBuffer(buffer.value());
                if (task != nullptr) {
                    takeHeld(task->heldBuffers, heldHandle(object.value(), index));
                }
            }
            return buffer;
        }
        if (object.status() != Status::Remote) {
            return object.status();
        }
    }
    // Another node's pool: its node hands out the buffer, if it shares memory with this one.
    return forwardRemoteAllocate(RemoteService::PoolAllocate, id, 0);
}

Status BufferPoolManager::Return(ObjectId id, void* buffer)
{
    Task* const task = memory_area::callerTask();
    const uint16_t holder = memory_area::holderOf(task, BufferPool::kSystemHolder);
    {
        Lock lock;
        const Result<PoolObject*> object = lookup(id);
        if (object.ok()) {
            BufferPool& pool = object.value()->pool;
            // Off the caller's list only if the caller holds it: release() then
            // succeeds. A system buffer is on no list.
            const uint32_t index = pool.indexOfBuffer(buffer);
            uint16_t current = BufferPool::kFreeMark;
            if (task != nullptr && pool.holderOf(index, current) && current == holder) {
                giveHeld(task->heldBuffers, heldHandle(object.value(), index), pool.linksOf(index));
            }
            return pool.release(buffer, holder);
        }
        if (object.status() != Status::Remote) {
            return object.status();
        }
    }
    return forwardRemoteReturn(RemoteService::PoolReturn, id, buffer);
}

Result<void*> BufferPoolManager::AllocateLent(ObjectId id)
{
    Lock lock;
    const Result<PoolObject*> object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    return object.value()->pool.allocate(BufferPool::kLentHolder);
}

Status BufferPoolManager::ReturnLent(ObjectId id, void* buffer)
{
    Lock lock;
    const Result<PoolObject*> object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    return object.value()->pool.release(buffer, BufferPool::kLentHolder);
}

Result<BufferPoolStatistics> BufferPoolManager::GetStatistics(ObjectId id)
{
    Lock lock;
    const Result<PoolObject*> object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    if (object.value()->pool.isCorrupted()) {
        return Status::Corrupted;
    }
    return object.value()->pool.statistics();
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> BufferPoolManager::NameToObject(const char* name, Visibility askingScope)
{
    return memory_area::nameToObject(poolTable, start, name, askingScope);
}

DCOS_CONFIGURATION_SERVICE Status BufferPoolManager::AddObjects(size_t count) { return memory_area::addObjects(poolTable, start, count); }

DCOS_CONFIGURATION_SERVICE Status BufferPoolManager::XferOwnership(ObjectId id, ObjectId newOwner)
{
    return memory_area::transferObject(poolTable, lookup, id, newOwner, BufferPool::kSystemHolder);
}

DCOS_CONFIGURATION_SERVICE Status BufferPoolManager::XferOwnership(ObjectId id, void* buffer, ObjectId newOwner)
{
    return memory_area::transferMemory(
        lookup, [](PoolObject* object) -> BufferPool& { return object->pool; }, id, buffer, newOwner,
        BufferPool::kSystemHolder, [](PoolObject* object, uint32_t index, uint8_t* links, Task* from, Task* to) {
            memory_area::moveHeld(&Task::heldBuffers, from, to, heldHandle(object, index), links, takeHeld, giveHeld);
        });
}

DCOS_CONFIGURATION_SERVICE unsigned BufferPoolManager::recoverResourcesOf(ObjectId deadTask)
{
    if (deadTask.isNull() || deadTask.type() != ObjectType::Task) {
        return 0;
    }
    // Called by the task agent with interrupts already disabled: the
    // buffers the task held, from its list, then the pools it owns.
    Lock lock;
    const Result<Task*> task = TaskManager::resolve(deadTask);
    size_t recovered = reclaimHeldBuffers(task.ok() ? task.value() : nullptr, memory_area::holderOfTask(deadTask));
    recovered += poolTable.forEachOwnedBy(deadTask, [](ObjectId id, PoolObject*& object) { remove(id, *object); });
    return static_cast<unsigned>(recovered);
}

uint32_t BufferPoolManager::recoveryWalks() { return recoveryWalkCount; }

bool BufferPoolManager::overlapsArea(uintptr_t begin, uintptr_t end)
{
    // A free slot's area is empty, [0, 0), and overlaps nothing.
    const PoolArea* const activeEnd = poolAreas + poolTable.activeCount();
    for (const PoolArea* area = poolAreas; area != activeEnd; ++area) {
        if (begin < area->end && area->begin < end) {
            return true;
        }
    }
    return false;
}

bool BufferPoolManager::snapshot(size_t slot, PoolInfo& info)
{
    Lock lock;
    if (slot >= poolTable.activeCount() || !pools[slot].inUse() || !pools[slot].pool.inService()) {
        return false;
    }
    const PoolObject& object = pools[slot];
    info.id = object.id;
    info.owner = poolTable.ownerOf(object.id).value();
    info.statistics = object.pool.statistics();
    info.corrupted = object.pool.isCorrupted();
    const char* name = poolTable.nameOf(object.id).value();
    size_t i = 0;
    for (; i + 1 < sizeof info.name && name[i] != '\0'; ++i) {
        info.name[i] = name[i];
    }
    info.name[i] = '\0';
    return true;
}

size_t BufferPoolManager::activeCount()
{
    Lock lock;
    start();
    return poolTable.activeCount();
}

size_t BufferPoolManager::usedCount()
{
    Lock lock;
    return poolTable.usedCount();
}

size_t BufferPoolManager::capacity() { return kPoolCapacity; }

DCOS_RESOURCE_RECOVERY(bufferPoolRecovery, "buffer pool", recoverPools);

ObjectTableView bufferPoolTableView()
{
    return poolTable.view();
}

} // namespace dcos::internal

namespace dcos {

using internal::BufferPool;
using internal::BufferPoolManager;

// Allocate and Return are defined here rather than in BufferPoolAgent.cpp,
// beside the pool table, so that the common case runs in the agent's own
// call: under the interrupt guard, the inline lookup of the pool object by
// its id (fastObjectOf) and the pool's inline pop or push
// (BufferPool::tryAllocate, tryRelease). Every other
// case, errors included, goes to the manager's complete service, which
// resolves the id again under its own guard and gives the precise status.
// A task's id never has kFreeMark in its low half (its type is the task's),
// as tryAllocate requires of the holder.

Result<void*> BufferPoolAgent::Allocate(ObjectId id)
{
    {
        const arch_x86::InterruptGuard guard;
        internal::PoolObject* const object = internal::fastObjectOf(id);
        if (object->id == id) [[likely]] {
            // A task's allocation and the system's are two inline paths, as
            // in Return below.
            internal::Task* const task = internal::memory_area::callerTask();
            if (task != nullptr) [[likely]] {
                if (void* buffer = object->pool.tryAllocate(
                        [task] { return task->id.raw(); },
                        [object, task](uint32_t index, uint8_t*) {
                            internal::HeldList::take(task->heldBuffers, internal::heldHandle(object, index),
                                                     internal::heldLinks);
                        }))
                    [[likely]] {
                    return buffer;
                }
            } else if (void* buffer = object->pool.tryAllocate([] { return uint32_t{BufferPool::kSystemHolder}; })) {
                return buffer;
            }
        }
    }
    return BufferPoolManager::Allocate(id);
}

Status BufferPoolAgent::Return(ObjectId id, void* buffer)
{
    {
        const arch_x86::InterruptGuard guard;
        internal::PoolObject* const object = internal::fastObjectOf(id);
        if (object->id == id) [[likely]] {
            // A task's return and the system's are two inline paths: the
            // task's knows its holder and its list from the one test of the
            // caller, instead of keeping the holder word in a register to
            // test it again for the list, which made GCC spill the words it
            // had loaded.
            internal::Task* const task = internal::memory_area::callerTask();
            if (task != nullptr) [[likely]] {
                if (object->pool.tryRelease(
                        buffer, [task] { return task->id.raw(); },
                        [object, task](uint32_t index, uint8_t* links) {
                            internal::HeldList::give(task->heldBuffers, internal::heldHandle(object, index), links,
                                                     internal::heldLinks);
                        }))
                    [[likely]] {
                    return Status::Ok;
                }
            } else if (object->pool.tryRelease(buffer, [] { return uint32_t{BufferPool::kSystemHolder}; })) {
                return Status::Ok;
            }
        }
    }
    return BufferPoolManager::Return(id, buffer);
}

} // namespace dcos
