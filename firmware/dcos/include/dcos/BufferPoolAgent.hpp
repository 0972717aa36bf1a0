// The buffer pool memory agent's application interface (seed 7.7).
//
// A pool is a physically contiguous area divided into buffers of one fixed
// size, at least 4 bytes. Allocate and Return cost O(1) and never block, so
// a control loop can use them at any rate, and from interrupt handlers.
//
// Where the memory comes from: the application owns the area. It declares a
// static array sized with AreaBytes and passes it to Create; the pool keeps
// its bookkeeping (twelve bytes per buffer) at the start of that area and
// the buffers after it. The kernel therefore has no memory of its own to run
// out of, the size of every pool is fixed at build time, and Delete hands the
// area back to the application unchanged in size.
//
//     alignas(8) static uint8_t area[dcos::BufferPoolAgent::AreaBytes(64, 32)];
//     const ObjectId pool = bufferPoolAgent.Create(area, sizeof area, 64, "frames", Visibility::Local).value();
//     void* frame = bufferPoolAgent.Allocate(pool).value();  // NoMemory when all 32 are out
//     bufferPoolAgent.Return(pool, frame);
//
// Ownership. The pool object belongs to the task that created it (Delete and
// XferOwnership need the owner or a super user). Any task may Allocate from
// a pool; each buffer is then held by the task that allocated it, and only
// that task may Return it (NotOwner otherwise) until it hands the buffer on
// with XferOwnership(pool, buffer, task). A buffer allocated in an interrupt
// handler, or handed to the null id, is held by the system and any task may
// return it. When a task ends, resource recovery returns every buffer it
// still holds and deletes every pool it owns, even while other tasks hold
// buffers from it (their Return then fails with StaleId; the area itself is
// static application memory and stays valid).
//
// Corruption. The pool keeps all its bookkeeping in the state words at the
// start of the area, none inside the buffers (the free list is threaded
// through the state words), so a task that writes into a buffer after
// returning it spoils only its own data. Every state word carries a check
// bound to the pool and the buffer, which the pool verifies before it acts
// on the word. A buffer returned twice, a pointer into the pool that is not
// the start of a buffer, or a state word that a stray write overwrote makes
// the call fail with Corrupted and disables the pool: every later
// call except Delete fails with Corrupted, as the seed prescribes, and no
// buffer is ever handed out twice. A pointer outside the pool is refused with
// InvalidArgument and leaves the pool in service, because it cannot have
// damaged the pool (typically the caller named the wrong pool).
//
// Errors common to every primitive that takes a pool id: InvalidId for the
// null id, a forged index or a free slot; WrongType for an id of another
// object type; StaleId for a pool deleted since; Remote for a pool on
// another node the network tables do not know. Allocate and Return of a
// pool on another node that shares this node's memory (the dual-Pentium
// board's other node) are carried by the remote agent; across a fieldbus
// they fail with NotSupported, since nobody there can address the buffer
// (docs/protocols/remote-transactions.md, "Pools and heaps").
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// Usage of one buffer pool, as GetStatistics reports it.
struct BufferPoolStatistics {
    /// The buffer size given to Create, in bytes.
    uint32_t bufferSize = 0;
    /// Number of buffers the pool holds.
    uint32_t totalBuffers = 0;
    /// Buffers available to Allocate now.
    uint32_t freeBuffers = 0;
    /// The fewest free buffers there have been since Create (low-water mark).
    uint32_t lowWaterMark = 0;
    /// Successful Allocate calls since Create.
    uint32_t allocations = 0;
    /// Allocate calls that found the pool empty (NoMemory).
    uint32_t failedAllocations = 0;
    /// Successful Return calls since Create, including returns by resource recovery.
    uint32_t returns = 0;
};

/// The buffer pool memory agent interface object (seed 7.7, Table 9.6).
///
/// The class has no state; use the object bufferPoolAgent. Allocate, Return,
/// GetStatistics and the buffer form of XferOwnership cost O(1); Create and
/// the configuration services cost O(N) in the number of pool and heap slots.
class BufferPoolAgent {
public:
    /// Smallest buffer size Create accepts, in bytes (seed 7.7).
    static constexpr size_t kMinimumBufferSize = 4;
    /// Most buffers one pool can hold.
    static constexpr size_t kMaximumBuffers = 0xFFFE;

    /// Distance in bytes between consecutive buffers: the size rounded up to 4.
    static constexpr size_t Stride(size_t bufferSize) { return (bufferSize + 3) & ~size_t{3}; }

    /// Bytes an 8-byte aligned area needs to hold @p bufferCount buffers of @p bufferSize bytes.
    ///
    /// The pool keeps twelve bytes per buffer at the start of the area (a
    /// 32-bit state word, and two links of the holding task's list, so that
    /// recovery finds what a task held without a search), padded to 8 bytes,
    /// and the buffers after it. Buffers start on a
    /// 4-byte boundary, and on an 8-byte boundary when the size is a multiple of 8.
    static constexpr size_t AreaBytes(size_t bufferSize, size_t bufferCount)
    {
        return ((bufferCount * 12 + 7) & ~size_t{7}) + bufferCount * Stride(bufferSize);
    }

    /// Creates a pool of as many @p bufferSize byte buffers as fit in the
    /// area at @p area of @p areaBytes bytes, owned by the calling task.
    /// O(N) in the pool and heap slots (the overlap check) plus O(buffers).
    ///
    /// The area must stay valid and untouched by the application (except
    /// inside allocated buffers) until the pool is deleted. Create aligns its
    /// start up to 8 bytes. @p name (at most 15 characters, or null or empty)
    /// is the name NameToObject finds. Fails with InvalidArgument for a
    /// buffer size below 4, an area too small for one buffer or holding more
    /// than kMaximumBuffers, a null area, a bad name or visibility;
    /// AlreadyExists when the area overlaps another pool's or heap's area;
    /// TableFull when every active slot is used; InInterrupt in an interrupt handler.
    static Result<ObjectId> Create(void* area, size_t areaBytes, size_t bufferSize, const char* name,
                            Visibility visibility);

    /// Deletes the pool; every copy of its id turns stale and the area is the application's again. O(1).
    ///
    /// Only the owner or a super user may delete a pool (NotOwner). Fails
    /// with Busy while any buffer is allocated, so that no task is left
    /// writing into an area that is being reused; a corrupted pool can
    /// always be deleted, since that is the only way out (seed 7.7). Also
    /// fails with InInterrupt and the id errors.
    static Status Delete(ObjectId pool);

    /// Takes a free buffer from the pool, held by the calling task (by the
    /// system in an interrupt handler). O(1); never blocks.
    ///
    /// Fails with NoMemory when no buffer is free (counted in the
    /// statistics; poll again or use a bigger pool), Corrupted when the
    /// pool is or turns out to be corrupted, and the id errors.
    static Result<void*> Allocate(ObjectId pool);

    /// Gives the buffer @p buffer back to the pool. O(1).
    ///
    /// Fails with InvalidArgument for a pointer outside the pool (the pool
    /// stays in service); NotOwner when another task holds the buffer;
    /// Corrupted, disabling the pool, for a buffer that is already free (a
    /// double return), a pointer inside the pool that is not the start of a
    /// buffer, or overwritten bookkeeping; and the id errors.
    static Status Return(ObjectId pool, void* buffer);

    /// Reports the pool's usage (the seed's GetUsageInfo). O(1).
    ///
    /// Fails with Corrupted for a corrupted pool, and the id errors.
    static Result<BufferPoolStatistics> GetStatistics(ObjectId pool);

    /// Configuration service: returns the id of the pool named @p name on this node. O(N).
    ///
    /// Fails with NotFound, and InInterrupt in an interrupt handler.
    static Result<ObjectId> NameToObject(const char* name);

    /// Configuration service: activates @p count more pool slots. Privileged. O(count).
    ///
    /// Eight slots are active from the start. @p count must be a non-zero
    /// multiple of eight (InvalidArgument) and the total may not exceed the
    /// capacity built into the kernel (TableFull). Also fails with
    /// NotPermitted and InInterrupt.
    static Status AddObjects(size_t count);

    /// Gives the pool @p pool to the task @p newOwner, or to the system when
    /// @p newOwner is the null id. O(1).
    ///
    /// The owner or a super user may transfer a pool (NotOwner). The buffers
    /// allocated from it keep their holders. Fails with the id errors of
    /// @p newOwner when it is not a live local task, InInterrupt, and the id errors.
    static Status XferOwnership(ObjectId pool, ObjectId newOwner);

    /// Hands the allocated buffer @p buffer, held by the calling task, to
    /// the task @p newOwner, or to the system when @p newOwner is the null
    /// id. O(1).
    ///
    /// Use it when a buffer travels to another task, so that the receiver may
    /// Return it and so that the buffer is not recovered when the sender
    /// ends. A buffer held by the system may be taken by any task. Fails
    /// with NotOwner when another task holds the buffer, InvalidArgument for
    /// a pointer outside the pool, Corrupted as Return does, the id errors of
    /// @p newOwner when it is not a live local task, InInterrupt, and the id errors.
    static Status XferOwnership(ObjectId pool, void* buffer, ObjectId newOwner);
};

/// The object through which applications call the buffer pool memory agent.
inline constexpr BufferPoolAgent bufferPoolAgent{};

} // namespace dcos
