// The buffer pool memory agent's kernel side (seed 7.7).
//
// The manager keeps the table of pool objects (an ObjectTable of pointers
// into a static array, DCOS_CONFIG_POOL_CAPACITY slots, eight active at
// start) and implements the primitives dcos::BufferPoolAgent forwards to
// it, with the contracts documented there. The algorithm itself is
// internal::BufferPool; the manager adds ids, ownership, the holder of each
// buffer (the caller's task index, or the system in an interrupt handler),
// serialisation and resource recovery.
//
// Serialisation: every step runs with interrupts disabled, and costs O(1)
// except the overlap check of Create (O(pool and heap slots)), NameToObject,
// AddObjects and recovery. Create lays out the buffers (O(buffers)) with
// interrupts enabled: the slot and the area are reserved first, so no other
// Create can take the same memory meanwhile.
//
// The manager is usable before static constructors run and needs no start
// call: the first eight slots are activated on first use, and the table
// takes the node id from localNode() whenever it is empty.
#pragma once

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/ObjectTable.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// A consistent copy of one pool's state, for listings such as the console.
struct PoolInfo {
    /// The pool's id.
    ObjectId id;
    /// The owning task, or null for a pool owned by the system.
    ObjectId owner;
    /// The pool's usage counters.
    BufferPoolStatistics statistics;
    /// Whether the pool found its bookkeeping corrupted and refuses every call.
    bool corrupted = false;
    /// The pool's name; empty for an unnamed pool.
    char name[16] = {};
};

/// The buffer pool memory agent's kernel side; see dcos/BufferPoolAgent.hpp for the contracts.
class BufferPoolManager {
public:
    /// Implements BufferPoolAgent::Create for the calling task.
    static Result<ObjectId> Create(void* area, size_t areaBytes, size_t bufferSize, const char* name,
                                   Visibility visibility);
    /// Implements BufferPoolAgent::Delete.
    static Status Delete(ObjectId pool);
    /// Implements BufferPoolAgent::Allocate.
    static Result<void*> Allocate(ObjectId pool);
    /// Implements BufferPoolAgent::Return.
    static Status Return(ObjectId pool, void* buffer);
    /// Allocate of a buffer or segment lent to a task of another node,
    /// held by the lent tag (BufferPool::kLentHolder), whoever calls: the
    /// remote agent's worker (RemoteMemoryHolds.hpp). O(1).
    static Result<void*> AllocateLent(ObjectId pool);
    /// Return of a lent buffer, by the remote agent for the node that held it. O(1).
    static Status ReturnLent(ObjectId pool, void* buffer);
    /// Implements BufferPoolAgent::GetStatistics.
    static Result<BufferPoolStatistics> GetStatistics(ObjectId pool);
    /// Finds a pool visible from @p askingScope by name. O(N).
    static Result<ObjectId> NameToObject(const char* name, Visibility askingScope);
    /// Implements BufferPoolAgent::AddObjects.
    static Status AddObjects(size_t count);
    /// Implements BufferPoolAgent::XferOwnership for the pool object.
    static Status XferOwnership(ObjectId pool, ObjectId newOwner);
    /// Implements BufferPoolAgent::XferOwnership for one buffer.
    static Status XferOwnership(ObjectId pool, void* buffer, ObjectId newOwner);

    /// Returns every buffer @p deadTask holds, found from its held list,
    /// then deletes every pool it owns, whatever other tasks still hold.
    /// Returns the number of buffers and pools recovered. O(buffers held +
    /// pools owned); when the list was lost (HeldList.hpp), O(buffers of
    /// all pools) instead.
    static unsigned recoverResourcesOf(ObjectId deadTask);
    /// How many recoveries found a held list lost and walked every pool instead.
    static uint32_t recoveryWalks();

    /// Whether [begin, end) overlaps the area of a pool. O(N). Call with interrupts disabled.
    static bool overlapsArea(uintptr_t begin, uintptr_t end);

    /// Copies the state of the pool in slot @p slot; false when the slot is
    /// free or inactive. O(1); listings walk slots 0 to activeCount() - 1.
    static bool snapshot(size_t slot, PoolInfo& info);
    /// Number of active pool slots.
    static size_t activeCount();
    /// Number of pools in existence.
    static size_t usedCount();
    /// Pool slots reserved at build time.
    static size_t capacity();
};

} // namespace dcos::internal
