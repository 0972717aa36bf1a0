#include <dcos/internal/BufferPool.hpp>
#include <dcos/internal/SegmentedHeap.hpp>

namespace dcos::internal {

namespace {

constexpr uint32_t kSegmentKind = 0x5345474Du; // "SEGM"
constexpr uint32_t kTagKind = 0x54414753u;     // "TAGS"

constexpr uintptr_t roundUp8(uintptr_t value) { return (value + 7) & ~uintptr_t{7}; }

} // namespace

Status SegmentedHeap::initialise(void* area, size_t areaBytes, uint32_t salt)
{
    *this = SegmentedHeap{};
    const uintptr_t begin = reinterpret_cast<uintptr_t>(area);
    if (area == nullptr || areaBytes > UINTPTR_MAX - begin) {
        return Status::InvalidArgument;
    }
    const uintptr_t aligned = roundUp8(begin);
    if (aligned - begin > areaBytes) {
        return Status::InvalidArgument;
    }
    const size_t usable = (areaBytes - (aligned - begin)) & ~size_t{7};
    if (usable < kSmallestSegment || usable > kMaximumHeapBytes) {
        return Status::InvalidArgument;
    }
    base_ = reinterpret_cast<uint8_t*>(aligned);
    areaBegin_ = begin;
    areaEnd_ = begin + areaBytes;
    size_ = static_cast<uint32_t>(usable);
    salt_ = salt;
    // One free segment spans the heap.
    writeFreeSize(0, size_);
    setWord(4, kNone);
    setWord(8, kNone);
    head_ = 0;
    freeSegments_ = 1;
    freeBytes_ = size_;
    lowWater_ = size_;
    return Status::Ok;
}

Result<void*> SegmentedHeap::allocate(size_t bytes, uint16_t holder)
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    if (bytes == 0) {
        return Status::InvalidArgument;
    }
    if (bytes > size_) {
        ++failedAllocations_;
        return Status::NoMemory;
    }
    const uint32_t needed = static_cast<uint32_t>(HeapAgent::SegmentBytes(bytes));

    // First fit: check each free segment and its back link on the way.
    uint32_t previous = kNone;
    uint32_t current = head_;
    uint32_t currentSize = 0;
    uint32_t steps = 0;
    while (current != kNone) {
        if (++steps > freeSegments_ || !isLink(current) || !checkFree(current, currentSize)
            || word(current + 4) != previous) {
            return fail();
        }
        if (currentSize >= needed) {
            break;
        }
        previous = current;
        current = word(current + 8);
    }
    if (current == kNone) {
        if (steps != freeSegments_) {
            return fail(); // Free segments the list no longer reaches.
        }
        ++failedAllocations_;
        return Status::NoMemory;
    }

    // The segment after a free one must be allocated and know its predecessor is free.
    const uint32_t after = current + currentSize;
    Allocated afterHeader{};
    if (after < size_ && (!checkAllocated(after, afterHeader) || !afterHeader.previousFree)) {
        return fail();
    }
    const uint32_t next = word(current + 8);
    if (next != kNone && word(next + 4) != current) {
        return fail();
    }

    // Every word involved was checked; now the heap changes.
    uint32_t segment;
    uint32_t segmentSize;
    bool previousFree;
    if (currentSize - needed >= kSmallestSegment) {
        // Cut the allocation from the end: the remainder keeps its list place.
        const uint32_t remainder = currentSize - needed;
        writeFreeSize(current, remainder);
        segment = current + remainder;
        segmentSize = needed;
        previousFree = true;
    } else {
        unlink(current);
        --freeSegments_;
        segment = current;
        segmentSize = currentSize;
        previousFree = false; // A free segment never follows another free one.
    }
    writeAllocated(segment, segmentSize, previousFree, holder);
    if (after < size_) {
        writeAllocated(after, afterHeader.size, false, afterHeader.holder);
    }
    freeBytes_ -= segmentSize;
    if (freeBytes_ < lowWater_) {
        lowWater_ = freeBytes_;
    }
    ++allocatedSegments_;
    ++allocations_;
    return static_cast<void*>(base_ + segment + kHeaderBytes);
}

Status SegmentedHeap::release(void* segment, uint16_t holder)
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    Allocated header{};
    const Result<uint32_t> offset = allocatedOffsetOf(segment, holder, header);
    if (!offset.ok()) {
        return offset.status();
    }
    uint32_t freedEnd;
    return releaseAt(offset.value(), header, freedEnd);
}

Status SegmentedHeap::transfer(void* segment, uint16_t from, uint16_t to)
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    Allocated header{};
    const Result<uint32_t> offset = allocatedOffsetOf(segment, from, header);
    if (!offset.ok()) {
        return offset.status();
    }
    writeAllocated(offset.value(), header.size, header.previousFree, to);
    return Status::Ok;
}

size_t SegmentedHeap::reclaimHeldBy(uint16_t holder)
{
    size_t reclaimed = 0;
    uint32_t offset = 0;
    while (offset < size_ && !corrupted_) {
        if ((word(offset) & kAllocatedFlag) == 0) {
            uint32_t size;
            if (!checkFree(offset, size)) {
                (void)fail(); // Disables the heap; recovery has no one to tell.
                break;
            }
            offset += size;
            continue;
        }
        Allocated header{};
        if (!checkAllocated(offset, header)) {
            (void)fail(); // Disables the heap; recovery has no one to tell.
            break;
        }
        if (header.holder != holder) {
            offset += header.size;
            continue;
        }
        // The freed segment may merge with the free one before it; the walk
        // goes on after the merged segment, which ends on a segment boundary.
        uint32_t freedEnd;
        if (releaseAt(offset, header, freedEnd) != Status::Ok) {
            break;
        }
        ++reclaimed;
        offset = freedEnd;
    }
    return reclaimed;
}

Result<HeapStatistics> SegmentedHeap::statistics()
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    uint32_t largest = 0;
    uint32_t total = 0;
    uint32_t steps = 0;
    uint32_t previous = kNone;
    for (uint32_t current = head_; current != kNone; current = word(current + 8)) {
        uint32_t size;
        if (++steps > freeSegments_ || !isLink(current) || !checkFree(current, size)
            || word(current + 4) != previous) {
            return fail();
        }
        largest = size > largest ? size : largest;
        total += size;
        previous = current;
    }
    if (steps != freeSegments_ || total != freeBytes_) {
        return fail();
    }
    HeapStatistics statistics;
    statistics.heapBytes = size_;
    statistics.freeBytes = freeBytes_;
    statistics.usedBytes = size_ - freeBytes_;
    statistics.allocatedSegments = allocatedSegments_;
    statistics.freeSegments = freeSegments_;
    statistics.largestFreeSegment = largest != 0 ? largest - static_cast<uint32_t>(kHeaderBytes) : 0;
    statistics.lowWaterFreeBytes = lowWater_;
    statistics.allocations = allocations_;
    statistics.failedAllocations = failedAllocations_;
    statistics.returns = returns_;
    return statistics;
}

Status SegmentedHeap::audit()
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    uint32_t freeCount = 0;
    uint32_t allocatedCount = 0;
    uint32_t freeTotal = 0;
    bool previousFree = false;
    uint32_t offset = 0;
    while (offset < size_) {
        uint32_t size;
        if ((word(offset) & kAllocatedFlag) == 0) {
            if (previousFree || !checkFree(offset, size)) {
                return fail(); // Two adjacent free segments were not merged.
            }
            ++freeCount;
            freeTotal += size;
            previousFree = true;
        } else {
            Allocated header{};
            if (!checkAllocated(offset, header) || header.previousFree != previousFree) {
                return fail();
            }
            size = header.size;
            ++allocatedCount;
            previousFree = false;
        }
        offset += size;
    }
    if (offset != size_ || freeCount != freeSegments_ || allocatedCount != allocatedSegments_
        || freeTotal != freeBytes_) {
        return fail();
    }
    // Every listed segment was just seen free; a list of freeCount steps
    // with consistent back links visits each free segment exactly once.
    uint32_t steps = 0;
    uint32_t previous = kNone;
    for (uint32_t current = head_; current != kNone; current = word(current + 8)) {
        uint32_t size;
        if (++steps > freeCount || !isLink(current) || !checkFree(current, size) || word(current + 4) != previous) {
            return fail();
        }
        previous = current;
    }
    return steps == freeCount ? Status::Ok : fail();
}

uint32_t SegmentedHeap::word(uint32_t offset) const
{
    // The area belongs to the application and may be declared with any
    // type; memcpy is a single load whatever that type is.
    uint32_t value;
    __builtin_memcpy(&value, base_ + offset, sizeof value);
    return value;
}

void SegmentedHeap::setWord(uint32_t offset, uint32_t value) { __builtin_memcpy(base_ + offset, &value, sizeof value); }

uint16_t SegmentedHeap::seal(uint32_t offset, uint32_t first, uint16_t holder) const
{
    return static_cast<uint16_t>(
        mixBits(salt_ ^ kSegmentKind ^ (offset * 0x9E3779B1u) ^ (first * 0x85EBCA77u) ^ (holder * 0xC2B2AE3Du)) >> 16);
}

uint32_t SegmentedHeap::endTag(uint32_t size, uint32_t end) const
{
    return size ^ mixBits(salt_ ^ kTagKind ^ (end * 0x9E3779B1u));
}

bool SegmentedHeap::isLink(uint32_t link) const
{
    // Room for a whole smallest segment, so that its links can be read.
    return (link & kFlagMask) == 0 && link <= size_ - kSmallestSegment;
}

bool SegmentedHeap::checkFree(uint32_t offset, uint32_t& size) const
{
    const uint32_t first = word(offset);
    size = first & ~kFlagMask;
    // A free segment has no flags: it is not allocated and its predecessor is not free.
    if ((first & kFlagMask) != 0 || size < kSmallestSegment || size > size_ - offset) {
        return false;
    }
    const uint32_t previous = word(offset + 4);
    const uint32_t next = word(offset + 8);
    return word(offset + size - 4) == endTag(size, offset + size) && (previous == kNone || isLink(previous))
           && (next == kNone || isLink(next));
}

bool SegmentedHeap::checkAllocated(uint32_t offset, Allocated& header) const
{
    const uint32_t first = word(offset);
    const uint32_t second = word(offset + 4);
    header.size = first & ~kFlagMask;
    header.holder = static_cast<uint16_t>(second);
    header.previousFree = (first & kPreviousFreeFlag) != 0;
    return (first & (kFlagMask & ~kPreviousFreeFlag)) == kAllocatedFlag && header.size >= kSmallestSegment
           && header.size <= size_ - offset && (second >> 16) == seal(offset, first, header.holder);
}

bool SegmentedHeap::checkListNeighbours(uint32_t offset) const
{
    const uint32_t previous = word(offset + 4);
    const uint32_t next = word(offset + 8);
    const bool previousOk = previous == kNone ? head_ == offset : word(previous + 8) == offset;
    return previousOk && (next == kNone || word(next + 4) == offset);
}

void SegmentedHeap::writeAllocated(uint32_t offset, uint32_t size, bool previousFree, uint16_t holder)
{
    const uint32_t first = size | kAllocatedFlag | (previousFree ? kPreviousFreeFlag : 0);
    setWord(offset, first);
    setWord(offset + 4, (static_cast<uint32_t>(seal(offset, first, holder)) << 16) | holder);
}

void SegmentedHeap::writeFreeSize(uint32_t offset, uint32_t size)
{
    setWord(offset, size);
    setWord(offset + size - 4, endTag(size, offset + size));
}

void SegmentedHeap::unlink(uint32_t offset)
{
    const uint32_t previous = word(offset + 4);
    const uint32_t next = word(offset + 8);
    if (previous == kNone) {
        head_ = next;
    } else {
        setWord(previous + 8, next);
    }
    if (next != kNone) {
        setWord(next + 4, previous);
    }
}

Result<uint32_t> SegmentedHeap::allocatedOffsetOf(void* segment, uint16_t holder, Allocated& header)
{
    const uintptr_t address = reinterpret_cast<uintptr_t>(segment);
    const uintptr_t base = reinterpret_cast<uintptr_t>(base_);
    if (size_ == 0 || address < base || address - base >= size_) {
        return Status::InvalidArgument; // Not this heap's memory: the heap is unharmed.
    }
    if (((address - base) & kFlagMask) != 0 || address - base < kHeaderBytes) {
        return fail(); // A wild pointer into the heap.
    }
    const uintptr_t offset = address - base - kHeaderBytes;
    // A free or merged segment (a double return) or an overwritten header fails here.
    if (!checkAllocated(static_cast<uint32_t>(offset), header)) {
        return fail();
    }
    if (header.holder != holder && header.holder != kSystemHolder) {
        return Status::NotOwner;
    }
    return static_cast<uint32_t>(offset);
}

Status SegmentedHeap::releaseAt(uint32_t offset, const Allocated& header, uint32_t& freedEnd)
{
    // Check both neighbours before anything is written.
    const uint32_t nextOffset = offset + header.size;
    bool mergeNext = false;
    uint32_t nextSize = 0;
    Allocated nextHeader{};
    if (nextOffset < size_) {
        if ((word(nextOffset) & kAllocatedFlag) == 0) {
            if (!checkFree(nextOffset, nextSize) || !checkListNeighbours(nextOffset)) {
                return fail();
            }
            mergeNext = true;
        } else if (!checkAllocated(nextOffset, nextHeader) || nextHeader.previousFree) {
            return fail();
        }
    }
    uint32_t previousOffset = 0;
    uint32_t previousSize = 0;
    if (header.previousFree) {
        if (offset < kSmallestSegment) {
            return fail();
        }
        previousSize = word(offset - 4) ^ endTag(0, offset); // The tag ends where this segment starts.
        uint32_t checkedSize;
        if (previousSize > offset || (previousSize & kFlagMask) != 0
            || !checkFree(offset - previousSize, checkedSize) || checkedSize != previousSize) {
            return fail();
        }
        previousOffset = offset - previousSize;
    }

    // Merge. An obsolete header is cleared so an old pointer to it reads as a double return.
    uint32_t start = offset;
    uint32_t total = header.size;
    if (mergeNext) {
        unlink(nextOffset);
        setWord(nextOffset, 0);
        setWord(nextOffset + 4, 0);
        total += nextSize;
        --freeSegments_;
    }
    if (header.previousFree) {
        setWord(offset, 0);
        setWord(offset + 4, 0);
        start = previousOffset;
        total += previousSize;
        writeFreeSize(start, total); // Already on the free list.
    } else {
        writeFreeSize(start, total);
        setWord(start + 4, kNone);
        setWord(start + 8, head_);
        if (head_ != kNone) {
            setWord(head_ + 4, start);
        }
        head_ = start;
        ++freeSegments_;
    }
    // The segment after the merged one is allocated; it now follows a free one.
    // After a merge with the successor it already had the flag set.
    if (!mergeNext && nextOffset < size_) {
        writeAllocated(nextOffset, nextHeader.size, true, nextHeader.holder);
    }
    freeBytes_ += header.size;
    --allocatedSegments_;
    ++returns_;
    freedEnd = start + total;
    return Status::Ok;
}

Status SegmentedHeap::fail()
{
    corrupted_ = true;
    return Status::Corrupted;
}

} // namespace dcos::internal
