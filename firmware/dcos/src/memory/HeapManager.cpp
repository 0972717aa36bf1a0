// The segmented heap memory agent's kernel side (seed 7.8): the heap table,
// holders, serialisation and resource recovery around internal::SegmentedHeap.
#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/internal/BufferPool.hpp>
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/HeapManager.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/MemoryAreaServices.hpp>
#include <dcos/internal/ObjectTable.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/ResourceRecovery.hpp>
#include <dcos/internal/SegmentedHeap.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos::internal {

namespace {

// Interrupt handlers may allocate and return segments, so the agent's
// bookkeeping runs with interrupts disabled.
using Lock = arch_x86::InterruptGuard;

// A heap object: the algorithm's state plus the area it covers.
struct HeapObject {
    SegmentedHeap heap;
    ObjectId id;
    bool inUse = false;
};

using HeapTable = ObjectTable<HeapObject*, kHeapCapacity, TaskOwnerKeys>;

constinit HeapTable heapTable(ObjectType::Heap, 0);
constinit HeapObject heaps[kHeapCapacity];
constinit bool started = false;
constinit uint32_t heapsCreated = 0;

size_t slotOf(ObjectId id) { return heapTable.slotNumber(id); }

// Activates the first slots on first use; call with interrupts disabled.
void start()
{
    if (!started) {
        (void)heapTable.AddObjects(kHeapsActiveAtBoot); // Cannot fail: checked by KernelConfig.hpp.
        started = true;
    }
    if (heapTable.usedCount() == 0 && heapTable.node() != localNode()) {
        (void)heapTable.setNode(localNode());
    }
}

// The id checks every primitive shares; call with interrupts disabled.
[[gnu::noinline]] Result<HeapObject*> resolveFully(ObjectId id)
{
    // The table gives InvalidId, WrongType, Remote (another node's object,
    // which Allocate and Return forward to the remote agent) and StaleId.
    start();
    const Result<HeapObject**> entry = heapTable.resolve(id);
    if (!entry.ok()) {
        return entry.status();
    }
    return *entry.value();
}

// Every service's lookup: the table's inline one, and on a miss the full
// resolve, which sets the tables up if need be and gives the reason.
[[gnu::always_inline]] inline Result<HeapObject*> lookup(ObjectId id)
{
    if (HeapObject* const* found = heapTable.find(id)) [[likely]] {
        return *found;
    }
    return resolveFully(id);
}

// Delete and XferOwnership of the heap need its owner or a super user.
Status checkOwnerOrSuperUser(ObjectId id)
{
    return heapTable.checkOwnerOrPrivileged(id, currentTaskId(), currentTaskIsSuperUser());
}

void remove(ObjectId id, HeapObject& object)
{
    (void)heapTable.Delete(id);
    // Only the slot's flag and id are cleared: the heap's class heads make
    // the object close to a kilobyte, which Create lays out anew anyway.
    object.inUse = false;
    object.id = ObjectId::null();
}

unsigned recoverHeaps(ObjectId deadTask) { return HeapManager::recoverResourcesOf(deadTask); }

// A segment's handle on its holder's list (HeldList.hpp): the heap's slot in
// the high 12 bits, the segment's offset in units of 8 bytes in the low 20.
static_assert(kHeapCapacity <= 0x1000, "a heap's slot takes 12 bits of a handle");
static_assert(((SegmentedHeap::kMaximumHeapBytes - SegmentedHeap::kSmallestSegment) >> 3) < 0x100000
                  && ((0xFFFu << 20) | ((SegmentedHeap::kMaximumHeapBytes - SegmentedHeap::kSmallestSegment) >> 3))
                         < kHeldHandleLimit,
              "every segment's offset fits a handle, and no handle is a list mark");
[[gnu::always_inline]] inline uint32_t heldHandle(const HeapObject* object, uint32_t offset)
{
    return (static_cast<uint32_t>(object - heaps) << 20) | (offset >> 3);
}

// HeldList's resolver: the links of the allocated segment a handle names, or
// null. A mark has a slot above every capacity.
[[gnu::always_inline]] inline uint8_t* heldLinks(uint32_t handle)
{
    const uint32_t slot = handle >> 20;
    if (slot >= kHeapCapacity) [[unlikely]] {
        return nullptr;
    }
    return heaps[slot].heap.linksIfAllocated((handle & 0xFFFFF) << 3);
}

// The list operations with this agent's resolver, out of line: the
// allocator around them costs hundreds of instructions, a call a handful.
[[gnu::noinline]] void takeHeld(HeldHead& head, uint32_t handle) { HeldList::take(head, handle, heldLinks); }

[[gnu::noinline]] void giveHeld(HeldHead& head, uint32_t handle, uint8_t* links)
{
    HeldList::give(head, handle, links, heldLinks);
}


// Allocate for @p task (null: the system) and put the segment on its list.
// Call with interrupts disabled.
[[gnu::always_inline]] inline Result<void*> allocateFor(HeapObject& object, size_t bytes, Task* task)
{
    const uint16_t holder = memory_area::holderOf(task, SegmentedHeap::kSystemHolder);
    const Result<void*> segment = object.heap.allocate(bytes, holder);
    if (segment.ok()) [[likely]] {
        if (task != nullptr) [[likely]] {
            HeldList::take(task->heldSegments, heldHandle(&object, object.heap.offsetOf(segment.value())), heldLinks);
        }
    }
    return segment;
}

// Return for @p task (null: the system) and take the segment off its list.
// Call with interrupts disabled.
[[gnu::always_inline]] inline Status releaseFor(HeapObject& object, void* segment, Task* task)
{
    const uint16_t holder = memory_area::holderOf(task, SegmentedHeap::kSystemHolder);
    SegmentedHeap::Released released;
    const Status status = object.heap.release(segment, holder, &released);
    // The segment's own links may be gone in the merge, so it is taken off
    // with the values release() read; a system segment is on no list.
    if (status == Status::Ok && task != nullptr && released.holder == holder) [[likely]] {
        HeldLinksCopy links(released.next, released.previous);
        HeldList::give(task->heldSegments, heldHandle(&object, object.heap.offsetOf(segment)), links.bytes, heldLinks);
    }
    return status;
}

constinit uint32_t recoveryWalkCount = 0;

// Gives back every segment the dead task held, from its list; when the list
// was lost, from a walk over every heap for its holder tag.
size_t reclaimHeldSegments(Task* task, uint16_t holder)
{
    return memory_area::reclaimHeld(
        task, &Task::heldSegments, heldLinks,
        [holder](uint32_t handle) { return heaps[handle >> 20].heap.reclaim((handle & 0xFFFFF) << 3, holder); },
        [holder] {
            // Only active slots can hold an object: the walk is O(active slots), not O(capacity).
            size_t reclaimed = 0;
            const HeapObject* const activeEnd = heaps + heapTable.activeCount();
            for (HeapObject* object = heaps; object != activeEnd; ++object) {
                if (object->inUse) {
                    reclaimed += object->heap.reclaimHeldBy(holder);
                }
            }
            return reclaimed;
        },
        recoveryWalkCount);
}

} // namespace

DCOS_CONFIGURATION_SERVICE Result<ObjectId> HeapManager::Create(void* area, size_t areaBytes, const char* name, Visibility visibility)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    const uintptr_t begin = reinterpret_cast<uintptr_t>(area);
    if (area == nullptr || areaBytes > UINTPTR_MAX - begin) {
        return Status::InvalidArgument;
    }
    const uintptr_t end = begin + areaBytes;
    // Laying out a heap is O(1), so the whole of Create runs with interrupts disabled.
    Lock lock;
    start();
    if (overlapsArea(begin, end) || BufferPoolManager::overlapsArea(begin, end)) {
        return Status::AlreadyExists;
    }
    const Result<ObjectId> created = heapTable.Create(currentTaskId(), name, visibility);
    if (!created.ok()) {
        return created.status();
    }
    const ObjectId id = created.value();
    HeapObject& object = heaps[slotOf(id)];
    object = HeapObject{};
    ++heapsCreated;
    const uint32_t salt = mixBits(static_cast<uint32_t>(begin) ^ (heapsCreated * 0x7F4A7C15u));
    const Status status = object.heap.initialise(area, areaBytes, salt);
    if (status != Status::Ok) {
        (void)heapTable.Delete(id);
        object = HeapObject{};
        return status;
    }
    object.id = id;
    object.inUse = true;
    *heapTable.resolve(id).value() = &object;
    return id;
}

DCOS_CONFIGURATION_SERVICE Status HeapManager::Delete(ObjectId id)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    Lock lock;
    const Result<HeapObject*> object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    const Status owner = checkOwnerOrSuperUser(id);
    if (owner != Status::Ok) {
        return owner;
    }
    const SegmentedHeap& heap = object.value()->heap;
    if (!heap.isCorrupted() && heap.allocatedCount() != 0) {
        return Status::Busy;
    }
    remove(id, *object.value());
    return Status::Ok;
}

Result<void*> HeapManager::Allocate(ObjectId id, size_t bytes)
{
    Task* const task = memory_area::callerTask();
    {
        Lock lock;
        const Result<HeapObject*> object = lookup(id);
        if (object.ok()) {
            return allocateFor(*object.value(), bytes, task);
        }
        if (object.status() != Status::Remote) {
            return object.status();
        }
    }
    // Another node's heap: its node hands out the segment, if it shares memory with this one.
    if (bytes > 0xFFFFFFFFu) {
        return Status::NoMemory;
    }
    return forwardRemoteAllocate(RemoteService::HeapAllocate, id, static_cast<uint32_t>(bytes));
}

Status HeapManager::Return(ObjectId id, void* segment)
{
    Task* const task = memory_area::callerTask();
    {
        Lock lock;
        const Result<HeapObject*> object = lookup(id);
        if (object.ok()) {
            return releaseFor(*object.value(), segment, task);
        }
        if (object.status() != Status::Remote) {
            return object.status();
        }
    }
    return forwardRemoteReturn(RemoteService::HeapReturn, id, segment);
}

Result<void*> HeapManager::AllocateLent(ObjectId id, size_t bytes)
{
    Lock lock;
    const Result<HeapObject*> object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    // On no task's list: the remote agent keeps the lent ones (RemoteMemoryHolds.hpp).
    return object.value()->heap.allocate(bytes, SegmentedHeap::kLentHolder);
}

Status HeapManager::ReturnLent(ObjectId id, void* segment)
{
    Lock lock;
    const Result<HeapObject*> object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    return object.value()->heap.release(segment, SegmentedHeap::kLentHolder);
}

Result<HeapStatistics> HeapManager::GetStatistics(ObjectId id)
{
    Lock lock;
    const Result<HeapObject*> object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    return object.value()->heap.statistics();
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> HeapManager::NameToObject(const char* name, Visibility askingScope)
{
    return memory_area::nameToObject(heapTable, start, name, askingScope);
}

DCOS_CONFIGURATION_SERVICE Status HeapManager::AddObjects(size_t count) { return memory_area::addObjects(heapTable, start, count); }

DCOS_CONFIGURATION_SERVICE Status HeapManager::XferOwnership(ObjectId id, ObjectId newOwner)
{
    return memory_area::transferObject(heapTable, lookup, id, newOwner, SegmentedHeap::kSystemHolder);
}

DCOS_CONFIGURATION_SERVICE Status HeapManager::XferOwnership(ObjectId id, void* segment, ObjectId newOwner)
{
    return memory_area::transferMemory(
        lookup, [](HeapObject* object) -> SegmentedHeap& { return object->heap; }, id, segment, newOwner,
        SegmentedHeap::kSystemHolder, [](HeapObject* object, uint32_t offset, uint8_t* links, Task* from, Task* to) {
            memory_area::moveHeld(&Task::heldSegments, from, to, heldHandle(object, offset), links, takeHeld, giveHeld);
        });
}

DCOS_CONFIGURATION_SERVICE unsigned HeapManager::recoverResourcesOf(ObjectId deadTask)
{
    if (deadTask.isNull() || deadTask.type() != ObjectType::Task) {
        return 0;
    }
    // Called by the task agent with interrupts already disabled: the
    // segments the task held, from its list, then the heaps it owns.
    Lock lock;
    const Result<Task*> task = TaskManager::resolve(deadTask);
    size_t recovered =
        reclaimHeldSegments(task.ok() ? task.value() : nullptr, memory_area::holderOfTask(deadTask));
    recovered += heapTable.forEachOwnedBy(deadTask, [](ObjectId id, HeapObject*& object) { remove(id, *object); });
    return static_cast<unsigned>(recovered);
}

uint32_t HeapManager::recoveryWalks() { return recoveryWalkCount; }

bool HeapManager::overlapsArea(uintptr_t begin, uintptr_t end)
{
    const HeapObject* const activeEnd = heaps + heapTable.activeCount();
    for (const HeapObject* object = heaps; object != activeEnd; ++object) {
        if (object->inUse && begin < object->heap.areaEnd() && object->heap.areaBegin() < end) {
            return true;
        }
    }
    return false;
}

bool HeapManager::snapshot(size_t slot, HeapInfo& info)
{
    Lock lock;
    if (slot >= heapTable.activeCount() || !heaps[slot].inUse) {
        return false;
    }
    HeapObject& object = heaps[slot];
    info.id = object.id;
    info.owner = heapTable.ownerOf(object.id).value();
    const Result<HeapStatistics> statistics = object.heap.statistics();
    info.corrupted = !statistics.ok();
    info.statistics = statistics.ok() ? statistics.value() : HeapStatistics{};
    info.statistics.heapBytes = static_cast<uint32_t>(object.heap.heapBytes()); // Known even when corrupted.
    const char* name = heapTable.nameOf(object.id).value();
    size_t i = 0;
    for (; i + 1 < sizeof info.name && name[i] != '\0'; ++i) {
        info.name[i] = name[i];
    }
    info.name[i] = '\0';
    return true;
}

size_t HeapManager::activeCount()
{
    Lock lock;
    start();
    return heapTable.activeCount();
}

size_t HeapManager::usedCount()
{
    Lock lock;
    return heapTable.usedCount();
}

size_t HeapManager::capacity() { return kHeapCapacity; }

DCOS_RESOURCE_RECOVERY(heapRecovery, "heap", recoverHeaps);

ObjectTableView heapTableView()
{
    return heapTable.view();
}

} // namespace dcos::internal

namespace dcos {

using internal::HeapManager;
using internal::SegmentedHeap;

// Allocate and Return are defined here rather than in HeapAgent.cpp,
// beside the heap table, so that they run the allocator from the agent's
// own call: under the interrupt guard, with the table's inline lookup. An id
// that lookup refuses goes to the manager's complete service, which
// resolves it again and gives the precise status.

Result<void*> HeapAgent::Allocate(ObjectId id, size_t bytes)
{
    {
        const arch_x86::InterruptGuard guard;
        if (internal::HeapObject* const* found = internal::heapTable.find(id)) [[likely]] {
            return internal::allocateFor(**found, bytes, internal::memory_area::callerTask());
        }
    }
    return HeapManager::Allocate(id, bytes);
}

Status HeapAgent::Return(ObjectId id, void* segment)
{
    {
        const arch_x86::InterruptGuard guard;
        if (internal::HeapObject* const* found = internal::heapTable.find(id)) [[likely]] {
            return internal::releaseFor(**found, segment, internal::memory_area::callerTask());
        }
    }
    return HeapManager::Return(id, segment);
}

} // namespace dcos
