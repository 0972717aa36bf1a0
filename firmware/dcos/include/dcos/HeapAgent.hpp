// The segmented heap memory agent's application interface (seed 7.8).
//
// A heap is a physically contiguous area from which segments of any size are
// allocated. Every segment carries a 16-byte header, starts on an 8-byte
// boundary and holds at least 8 bytes; a returned segment is merged with its
// free neighbours on both sides, so two free segments are never adjacent.
// Where the seed allocated first fit, walking the free list, DCOS keeps the
// free segments in size classes (a two-level segregated fit): Allocate and
// Return cost O(1) however fragmented the heap is. The price is that a
// request may fail while a free segment less than an eighth larger than it
// exists; GetStatistics reports exactly the largest request that succeeds.
// A heap is still costlier than a buffer pool, whose buffers are all alike.
//
// Where the memory comes from: as for pools, the application owns the area,
// typically a static array, and passes it to Create; the heap keeps all its
// bookkeeping inside that area (segment headers, and links and boundary tags
// in free segments). The kernel has no memory of its own to run out of.
//
//     alignas(8) static uint8_t area[16 * 1024];
//     const ObjectId heap = heapAgent.Create(area, sizeof area, "work", Visibility::Local).value();
//     void* table = heapAgent.Allocate(heap, 300).value();  // NoMemory when no free segment fits
//     heapAgent.Return(heap, table);
//
// Ownership follows the buffer pool agent: the heap object belongs to its
// creator; each segment is held by the task that allocated it (by the system
// when allocated in an interrupt handler) and only its holder may Return it
// until it hands it on with XferOwnership(heap, segment, task). Resource
// recovery returns the segments a dead task holds and deletes the heaps it
// owns, even while other tasks hold segments from them (their Return then
// fails with StaleId).
//
// Corruption: every allocated segment's header carries a check value bound to
// the heap, its position, its size and its holder; free segments carry a
// boundary tag bound to their position and doubly linked free-list links that
// are cross-checked. A segment returned twice, a pointer into the heap that is
// not the start of a segment, an overwritten header, tag or link make the
// call fail with Corrupted and disable the heap until it is deleted (seed
// 7.8). A pointer outside the heap is refused with InvalidArgument.
//
// Errors common to every primitive that takes a heap id: InvalidId, WrongType,
// StaleId and Remote, as for every agent. Allocate and Return of a heap on
// another node that shares this node's memory are carried as for pools
// (BufferPoolAgent.hpp); across a fieldbus they fail with NotSupported.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// Usage of one segmented heap, as GetStatistics reports it.
struct HeapStatistics {
    /// Bytes the heap manages: the area after alignment to 8 bytes.
    uint32_t heapBytes = 0;
    /// Bytes in free segments, headers included.
    uint32_t freeBytes = 0;
    /// Bytes in allocated segments, headers included; heapBytes - freeBytes.
    uint32_t usedBytes = 0;
    /// Number of allocated segments.
    uint32_t allocatedSegments = 0;
    /// Number of free segments (fragments).
    uint32_t freeSegments = 0;
    /// The largest request Allocate can satisfy now: the first free segment
    /// of the highest non-empty size class less its header (another segment
    /// of that class may be up to an eighth larger); 0 when none.
    uint32_t largestFreeSegment = 0;
    /// The fewest free bytes there have been since Create (low-water mark).
    uint32_t lowWaterFreeBytes = 0;
    /// Successful Allocate calls since Create.
    uint32_t allocations = 0;
    /// Allocate calls that found no free segment large enough (NoMemory).
    uint32_t failedAllocations = 0;
    /// Successful Return calls since Create, including returns by resource recovery.
    uint32_t returns = 0;
};

/// The segmented heap memory agent interface object (seed 7.8, Table 9.7).
///
/// The class has no state; use the object heapAgent. Allocate, Return,
/// GetStatistics and the segment form of XferOwnership cost O(1); Create and
/// the configuration services cost O(N) in the number of pool and heap slots.
class HeapAgent {
public:
    /// Bytes of the header in front of every segment (seed 7.8): the size
    /// and flags, the holder and its check, and the two links of the holding
    /// task's list, so that recovery finds what a task held without a search.
    static constexpr size_t kHeaderBytes = 16;
    /// Largest heap, in bytes: a segment's place in it must fit the 20 bits
    /// a held list's handle has for it (in units of 8 bytes).
    static constexpr size_t kMaximumHeapBytes = (size_t{1} << 23) - 64;
    /// Alignment of every segment, and the granularity of segment sizes.
    static constexpr size_t kAlignment = 8;
    /// Smallest number of bytes a segment holds.
    static constexpr size_t kMinimumSegment = 8;

    /// Bytes of heap a request of @p bytes consumes: header plus the request
    /// rounded up to 8, at least 8. Useful to size an area.
    static constexpr size_t SegmentBytes(size_t bytes)
    {
        return kHeaderBytes + (bytes < kMinimumSegment ? kMinimumSegment : (bytes + kAlignment - 1) & ~(kAlignment - 1));
    }

    /// Creates a heap over the area at @p area of @p areaBytes bytes, owned
    /// by the calling task. O(N) in the pool and heap slots (the overlap check).
    ///
    /// Create aligns the area's start up to 8 bytes and its length down to a
    /// multiple of 8; the area must stay valid and untouched by the
    /// application (except inside allocated segments) until the heap is
    /// deleted. Fails with InvalidArgument for a null area, fewer than 24
    /// bytes after alignment (one smallest segment), more than
    /// kMaximumHeapBytes (8 MiB less 64 bytes), a bad
    /// name or visibility; AlreadyExists when the area overlaps another
    /// pool's or heap's area; TableFull; InInterrupt.
    static Result<ObjectId> Create(void* area, size_t areaBytes, const char* name, Visibility visibility);

    /// Deletes the heap; every copy of its id turns stale. O(1).
    ///
    /// Only the owner or a super user may delete a heap (NotOwner). Fails
    /// with Busy while any segment is allocated, unless the heap is
    /// corrupted. Also fails with InInterrupt and the id errors.
    static Status Delete(ObjectId heap);

    /// Allocates a segment of at least @p bytes, held by the calling task
    /// (by the system in an interrupt handler). O(1); never blocks.
    ///
    /// The segment is 8-byte aligned and holds SegmentBytes(bytes) - 16 bytes
    /// or, when the rest of the free segment would be too small to use, up
    /// to 16 more. Fails with InvalidArgument for 0 bytes, NoMemory when
    /// @p bytes is more than GetStatistics' largestFreeSegment (counted in
    /// the statistics), Corrupted, and the id errors.
    static Result<void*> Allocate(ObjectId heap, size_t bytes);

    /// Returns the segment @p segment to the heap and merges it with its free neighbours. O(1).
    ///
    /// Fails with InvalidArgument for a pointer outside the heap (the heap
    /// stays in service); NotOwner when another task holds the segment;
    /// Corrupted, disabling the heap, for a segment already free (a double
    /// return), a pointer that is not the start of a segment, or overwritten
    /// bookkeeping; and the id errors.
    static Status Return(ObjectId heap, void* segment);

    /// Reports the heap's usage, including the largest request that can
    /// succeed (the seed's GetUsageInfo). O(1): Allocate and Return keep the
    /// counters.
    ///
    /// Fails with Corrupted for a corrupted heap, and the id errors.
    static Result<HeapStatistics> GetStatistics(ObjectId heap);

    /// Configuration service: returns the id of the heap named @p name on this node. O(N).
    static Result<ObjectId> NameToObject(const char* name);

    /// Configuration service: activates @p count more heap slots, a
    /// non-zero multiple of eight. Privileged. O(count).
    static Status AddObjects(size_t count);

    /// Gives the heap to the task @p newOwner, or to the system for the null id. O(1).
    ///
    /// The owner or a super user may transfer a heap (NotOwner); its
    /// segments keep their holders.
    static Status XferOwnership(ObjectId heap, ObjectId newOwner);

    /// Hands the allocated segment @p segment, held by the calling task, to
    /// the task @p newOwner, or to the system for the null id. O(1).
    ///
    /// A segment held by the system may be taken by any task. Fails like
    /// Return, and with the id errors of @p newOwner when it is not a live local task.
    static Status XferOwnership(ObjectId heap, void* segment, ObjectId newOwner);
};

/// The object through which applications call the segmented heap memory agent.
inline constexpr HeapAgent heapAgent{};

} // namespace dcos
