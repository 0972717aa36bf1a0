// The segmented heap memory agent's kernel side (seed 7.8).
//
// The manager keeps the table of heap objects (an ObjectTable of pointers
// into a static array, DCOS_CONFIG_HEAP_CAPACITY slots, eight active at
// start) and implements the primitives dcos::HeapAgent forwards to it, with
// the contracts documented there. The algorithm is internal::SegmentedHeap;
// the manager adds ids, ownership, the holder of each segment, serialisation
// and resource recovery.
//
// Serialisation: every step runs with interrupts disabled. Allocate, Return
// and GetStatistics cost O(1) (internal::SegmentedHeap is a two-level
// segregated fit, not the seed's first fit), so they hold interrupts off for
// a bounded time whatever the fragmentation.
#pragma once

#include <dcos/HeapAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// A consistent copy of one heap's state, for listings such as the console.
struct HeapInfo {
    /// The heap's id.
    ObjectId id;
    /// The owning task, or null for a heap owned by the system.
    ObjectId owner;
    /// The heap's usage; only heapBytes is valid when the heap is corrupted.
    HeapStatistics statistics;
    /// Whether the heap found its bookkeeping corrupted and refuses every call.
    bool corrupted = false;
    /// The heap's name; empty for an unnamed heap.
    char name[16] = {};
};

/// The segmented heap memory agent's kernel side; see dcos/HeapAgent.hpp for the contracts.
class HeapManager {
public:
    /// Implements HeapAgent::Create for the calling task.
    static Result<ObjectId> Create(void* area, size_t areaBytes, const char* name, Visibility visibility);
    /// Implements HeapAgent::Delete.
    static Status Delete(ObjectId heap);
    /// Implements HeapAgent::Allocate.
    static Result<void*> Allocate(ObjectId heap, size_t bytes);
    /// Implements HeapAgent::Return.
    static Status Return(ObjectId heap, void* segment);
    /// Allocate of a buffer or segment lent to a task of another node,
    /// held by the lent tag (BufferPool::kLentHolder), whoever calls: the
    /// remote agent's worker (RemoteMemoryHolds.hpp). O(1).
    static Result<void*> AllocateLent(ObjectId heap, size_t bytes);
    /// Return of a lent segment, by the remote agent for the node that held it. O(1).
    static Status ReturnLent(ObjectId heap, void* segment);
    /// Implements HeapAgent::GetStatistics.
    static Result<HeapStatistics> GetStatistics(ObjectId heap);
    /// Finds a heap visible from @p askingScope by name. O(N).
    static Result<ObjectId> NameToObject(const char* name, Visibility askingScope);
    /// Implements HeapAgent::AddObjects.
    static Status AddObjects(size_t count);
    /// Implements HeapAgent::XferOwnership for the heap object.
    static Status XferOwnership(ObjectId heap, ObjectId newOwner);
    /// Implements HeapAgent::XferOwnership for one segment.
    static Status XferOwnership(ObjectId heap, void* segment, ObjectId newOwner);

    /// Returns every segment @p deadTask holds, found from its held list,
    /// then deletes every heap it owns. Returns the number of segments and
    /// heaps recovered. O(segments held + heaps owned); when the list was
    /// lost (HeldList.hpp), O(segments of all heaps) instead.
    static unsigned recoverResourcesOf(ObjectId deadTask);
    /// How many recoveries found a held list lost and walked every heap instead.
    static uint32_t recoveryWalks();

    /// Whether [begin, end) overlaps the area of a heap. O(N). Call with interrupts disabled.
    static bool overlapsArea(uintptr_t begin, uintptr_t end);

    /// Copies the state of the heap in slot @p slot; false when the slot is
    /// free or inactive. O(1).
    static bool snapshot(size_t slot, HeapInfo& info);
    /// Number of active heap slots.
    static size_t activeCount();
    /// Number of heaps in existence.
    static size_t usedCount();
    /// Heap slots reserved at build time.
    static size_t capacity();
};

} // namespace dcos::internal
