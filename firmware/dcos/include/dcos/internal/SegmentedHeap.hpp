// The algorithm of a segmented heap (seed 7.8), free of kernel and hardware.
//
// The heap tiles a caller-supplied area with segments. Every segment starts
// on an 8-byte boundary with a 16-byte header; its size (header included) is
// a multiple of 8 and at least 24, so it holds at least 8 bytes:
//
//     allocated:  | size | A=1 | P | check:16 holder:16 | held next | held prev | data ...  |
//     free:       | size | A=0 | P=0 | prev link        | next link | ...        | end tag  |
//
// The first header word holds the size with two flags in its low bits: A, the
// segment is allocated, and P, the segment before it is free. An allocated
// segment's second word is the holder (a 16-bit tag the kernel derives from
// the task id) and a check value bound to the heap's salt, the segment's
// position, its size and flags (P excepted: see seal()) and its holder. A
// free segment uses its second word and its first data word for the links of
// a doubly linked free list, and its last word for a boundary tag: its size
// scrambled with its end position, so that a segment whose P flag is set
// finds where its free predecessor starts in O(1) and can check the find.
//
// Allocation is a two-level segregated fit (TLSF, Masmano et al. 2004), so
// that Allocate and Return cost O(1) whatever the fragmentation, where the
// seed's first fit walked the free list. Free segments are kept in one list
// per size class: below 64 bytes one class per 8 bytes; above, each power of
// two [2^k, 2^(k+1)) is cut into eight classes of equal width. Two bitmaps
// (one bit per power of two, one bit per class within it) say which lists
// are non-empty, so a bit scan (BSF/BSR on the i486) finds the smallest
// non-empty class whose every segment fits the request: the request is
// rounded up to the next class boundary first. When that finds nothing, the
// first segment of the request's own class is tried, so a request fails only
// when it is larger than that segment and than every segment of a higher
// class: statistics() reports exactly that limit as the largest request that
// can succeed. The allocation is cut from the start of the chosen segment and
// the remainder, unless under 24 bytes (then given with the allocation),
// goes to the list of its class. Return merges the segment with a free
// successor and a free predecessor at once (boundary tags), so no two free
// segments are ever adjacent.
//
// Every word is checked before any is written; a failed check (a double
// return, a pointer that is not a segment's start, an overwritten header,
// tag or link, a list that loops or loses segments) disables the heap, and
// every call then fails with Status::Corrupted until the owner deletes it.
// A header made obsolete by a merge is cleared, so an old pointer to a merged
// segment is recognised as a double return.
//
// An allocated segment's third and fourth words are the links of its
// holder's list (HeldList.hpp), which the kernel keeps: the heap lays them
// out, hands over their values on release() and transfer(), and finds them
// with linksIfAllocated().
//
// The class does no locking; its owner serialises calls.
#pragma once

#include <dcos/HeapAgent.hpp>
#include <dcos/internal/HeldList.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// A two-level segregated fit heap of variable-size segments in a caller-supplied contiguous area.
class SegmentedHeap {
public:
    /// The holder tag of segments that belong to the system: any holder may return them.
    static constexpr uint16_t kSystemHolder = 0xFFFF;
    /// The holder tag of segments lent to a task of another node
    /// (BufferPool::kLentHolder says why). Never a task's.
    static constexpr uint16_t kLentHolder = 0xFFFD;
    /// Bytes of a segment's header.
    static constexpr size_t kHeaderBytes = HeapAgent::kHeaderBytes;
    /// Alignment and size granularity of segments.
    static constexpr size_t kAlignment = HeapAgent::kAlignment;
    /// Smallest segment, header included: a 16-byte header and 8 bytes of data.
    static constexpr size_t kSmallestSegment = kHeaderBytes + HeapAgent::kMinimumSegment;
    /// Largest heap, in bytes.
    static constexpr size_t kMaximumHeapBytes = HeapAgent::kMaximumHeapBytes;

    /// What release() found in a segment before it freed it: its holder and
    /// the values of its held-list links.
    struct Released {
        uint16_t holder = kSystemHolder;
        uint32_t next = kHeldEnd;
        uint32_t previous = kHeldUnlisted;
    };

    /// Creates an unused heap; initialise() puts it in service.
    constexpr SegmentedHeap() = default;

    /// Makes the area at @p area of @p areaBytes bytes one free segment. O(1).
    ///
    /// The start is aligned up and the length down to 8 bytes. @p salt makes
    /// this heap's check values differ from any other's. Fails with
    /// InvalidArgument for a null area, fewer than 24 usable bytes or more
    /// than kMaximumHeapBytes; the heap is then unused.
    Status initialise(void* area, size_t areaBytes, uint32_t salt);

    /// Allocates a segment for at least @p bytes for @p holder. O(1).
    ///
    /// Fails with InvalidArgument for 0 bytes, NoMemory when the request is
    /// larger than statistics().largestFreeSegment, and Corrupted.
    Result<void*> allocate(size_t bytes, uint16_t holder);

    /// Returns @p segment on behalf of @p holder and merges it with its free neighbours. O(1).
    ///
    /// InvalidArgument for a pointer outside the heap; NotOwner when another
    /// holder than @p holder or the system holds it; Corrupted (the heap is
    /// disabled) for a free segment, a pointer that is not a segment's start,
    /// or bookkeeping that fails its checks.
    Status release(void* segment, uint16_t holder) { return release(segment, holder, nullptr); }
    /// release(), which on success also says in @p released who held the
    /// segment and what its links were (the merge may overwrite them).
    Status release(void* segment, uint16_t holder, Released* released);

    /// Hands @p segment, held by @p from or by the system, to the holder @p to. O(1).
    ///
    /// Fails as release() does. On success @p moved(offset, links,
    /// previousHolder) is called, with previousHolder @p from or kSystemHolder.
    template <typename Moved>
    Status transfer(void* segment, uint16_t from, uint16_t to, Moved moved)
    {
        uint32_t offset = 0;
        uint16_t previous = kSystemHolder;
        const Status status = transferOffset(segment, from, to, offset, previous);
        if (status == Status::Ok) {
            moved(offset, base_ + offset + 8, previous);
        }
        return status;
    }
    /// transfer() for callers that keep no lists.
    Status transfer(void* segment, uint16_t from, uint16_t to)
    {
        return transfer(segment, from, to, [](uint32_t, uint8_t*, uint16_t) {});
    }

    /// Frees the segment at @p offset if @p holder holds it; false (nothing
    /// changed) if not, or if the offset is not an allocated segment's.
    /// Recovery uses it on the items of a dead task's list. O(1).
    bool reclaim(uint32_t offset, uint16_t holder);

    /// The offset of the segment whose data starts at @p data, which
    /// allocate() just returned.
    uint32_t offsetOf(const void* data) const
    {
        return static_cast<uint32_t>(static_cast<const uint8_t*>(data) - base_ - kHeaderBytes);
    }
    /// The held-list links of the segment at @p offset, or null when the heap
    /// is corrupted or out of service, the offset lies beyond it or no
    /// allocated segment's checked header is there (so that a handle left
    /// from a heap deleted in the same slot never leads into a segment's
    /// data): for resolving a held list's handles. O(1).
    uint8_t* linksIfAllocated(uint32_t offset) const;

    /// Returns every segment @p holder holds; returns how many. O(segments).
    ///
    /// When a check fails the heap is disabled and the walk stops.
    size_t reclaimHeldBy(uint16_t holder);

    /// Usage counters plus the largest request that can succeed now: the
    /// first free segment of the highest non-empty class, less its header
    /// (another segment of that class may be up to an eighth larger). O(1).
    /// Checks that segment; fails with Corrupted.
    Result<HeapStatistics> statistics();

    /// Checks the whole heap: the segments tile the area, every header,
    /// tag and flag is right, no two free segments are adjacent, and the
    /// class lists hold exactly the free segments, each once, in its class,
    /// with consistent back links and bitmaps. O(segments). Returns Ok or Corrupted (and
    /// disables the heap). For tests and diagnostics.
    Status audit();

    /// Number of allocated segments. O(1).
    size_t allocatedCount() const { return allocatedSegments_; }
    /// Bytes in free segments, headers included. O(1).
    size_t freeBytes() const { return freeBytes_; }
    /// Bytes the heap manages.
    size_t heapBytes() const { return size_; }
    /// Whether a check failed; a corrupted heap refuses every call.
    bool isCorrupted() const { return corrupted_; }
    /// Whether initialise() succeeded.
    bool inService() const { return size_ != 0; }
    /// The first byte of the area given to initialise().
    uintptr_t areaBegin() const { return areaBegin_; }
    /// One past the last byte of the area given to initialise().
    uintptr_t areaEnd() const { return areaEnd_; }

private:
    static constexpr uint32_t kNone = 0xFFFFFFFFu;
    static constexpr uint32_t kAllocatedFlag = 1;
    static constexpr uint32_t kPreviousFreeFlag = 2;
    static constexpr uint32_t kFlagMask = 7;
    // Eight classes per power of two: a request rounded up to a class
    // boundary is at most an eighth larger, and the heads of one heap take
    // 576 bytes (sixteen classes would double that for every heap slot).
    static constexpr uint32_t kClassBits = 3;
    static constexpr uint32_t kClasses = 1u << kClassBits;
    // Class 0 holds the linear classes below 64 bytes; class k >= 1 holds
    // [2^(k+5), 2^(k+6)) bytes, up to the largest heap (8 MiB: level 17).
    static constexpr uint32_t kLevels = 18;

    // A size class: the power of two (level) and the class within it.
    struct SizeClass {
        uint32_t level;
        uint32_t index;
    };

    // What a checked allocated header says.
    struct Allocated {
        uint32_t size;
        uint16_t holder;
        bool previousFree;
    };

    [[gnu::always_inline]] static constexpr SizeClass classOf(uint32_t size);
    // classOf() of @p needed rounded up to the next class boundary (the
    // class whose every segment fits it), in one pass.
    [[gnu::always_inline]] static constexpr SizeClass roundedClassOf(uint32_t needed);
    // Whether roundedClassOf() agrees with classOf() of the rounded size
    // for every segment size up to @p limit (a compile-time check).
    static constexpr bool roundedClassesAgree(uint32_t limit);
    // The area belongs to the application and may be declared with any
    // type; memcpy is a single load or store whatever that type is.
    [[gnu::always_inline]] uint32_t word(uint32_t offset) const
    {
        uint32_t value;
        __builtin_memcpy(&value, base_ + offset, sizeof value);
        return value;
    }
    [[gnu::always_inline]] void setWord(uint32_t offset, uint32_t value)
    {
        __builtin_memcpy(base_ + offset, &value, sizeof value);
    }
    [[gnu::always_inline]] uint16_t seal(uint32_t offset, uint32_t first, uint16_t holder) const;
    [[gnu::always_inline]] uint32_t endTag(uint32_t size, uint32_t end) const;
    [[gnu::always_inline]] bool isLink(uint32_t link) const;
    [[gnu::always_inline]] bool checkFree(uint32_t offset, uint32_t& size) const;
    [[gnu::always_inline]] bool checkLinks(uint32_t offset) const;
    [[gnu::always_inline]] bool checkAllocated(uint32_t offset, Allocated& header) const;
    [[gnu::always_inline]] bool checkAllocatedFrame(uint32_t offset, uint32_t previousFreeFlag) const;
    // checkLinks() and the neighbours on the list of @p sizeClass linking back to @p offset.
    [[gnu::always_inline]] bool checkListed(uint32_t offset, SizeClass sizeClass) const;
    [[gnu::always_inline]] void writeAllocated(uint32_t offset, uint32_t size, bool previousFree, uint16_t holder);
    [[gnu::always_inline]] void insert(uint32_t offset, uint32_t size);
    [[gnu::always_inline]] void unlink(uint32_t offset, SizeClass sizeClass);
    // Moves @p sizeClass to the smallest non-empty class at or above it; false when none.
    [[gnu::always_inline]] bool findFrom(SizeClass& sizeClass) const;
    // Takes the first segment off the list of @p sizeClass; @p next follows it.
    [[gnu::always_inline]] void removeFirst(SizeClass sizeClass, uint32_t next);
    // Clears the bits of the class whose list just became empty.
    [[gnu::always_inline]] void emptied(SizeClass sizeClass);
    // Finds the offset of an allocated segment for release() and transfer().
    [[gnu::always_inline]] Result<uint32_t> allocatedOffsetOf(void* segment, uint16_t holder, Allocated& header);
    // Frees the checked allocated segment of @p size bytes at @p offset and
    // merges it; returns the end of the resulting free segment, or 0 when a
    // check failed (the heap is then disabled). The header comes as values,
    // not as an Allocated in memory, so that the caller need not store it.
    uint32_t releaseAt(uint32_t offset, uint32_t size, bool previousFree);
    Status transferOffset(void* segment, uint16_t from, uint16_t to, uint32_t& offset, uint16_t& previous);
    Status fail();

    uint8_t* base_ = nullptr;
    uintptr_t areaBegin_ = 0;
    uintptr_t areaEnd_ = 0;
    uint32_t size_ = 0;
    // size_ less a header while in service, 0 once corrupted: the one bound
    // Allocate and Return test first.
    uint32_t limit_ = 0;
    uint32_t freeBytes_ = 0;
    uint32_t freeSegments_ = 0;
    uint32_t allocatedSegments_ = 0;
    uint32_t lowWater_ = 0;
    uint32_t allocations_ = 0;
    uint32_t failedAllocations_ = 0;
    uint32_t returns_ = 0;
    uint32_t salt_ = 0;
    // Odd, derived from the salt by initialise(): the factor of the seals and
    // tags. Zero until then, so that a table of unused heaps is all zero and
    // lives in .bss, not in the image.
    uint32_t multiplier_ = 0;
    // Bit k: levelMaps_[k] is not zero.
    uint32_t levelMap_ = 0;
    // Bit i of levelMaps_[k]: the list heads_[k][i] is not empty. A head is
    // valid only while its bit is set.
    uint8_t levelMaps_[kLevels] = {};
    bool corrupted_ = false;
    uint32_t heads_[kLevels][kClasses] = {};
};

} // namespace dcos::internal
