#include <dcos/internal/BufferPool.hpp>
#include <dcos/internal/SegmentedHeap.hpp>

namespace dcos::internal {

namespace {

constexpr uint32_t kTagKind = 0x54414753u; // "TAGS"

constexpr uintptr_t roundUp8(uintptr_t value) { return (value + 7) & ~uintptr_t{7}; }

// The index of the highest set bit of a non-zero value. Written with XOR,
// not as 31 - clz, so that GCC emits a lone BSR.
constexpr uint32_t highestBit(uint32_t value) { return static_cast<uint32_t>(__builtin_clz(value)) ^ 31; }

} // namespace

constexpr SegmentedHeap::SizeClass SegmentedHeap::roundedClassOf(uint32_t needed)
{
    if (needed < kClasses * kAlignment) {
        return {0, static_cast<uint32_t>(needed / kAlignment)}; // A multiple of 8 below 64 is a class boundary.
    }
    // The classes of [2^p, 2^(p+1)) are 2^(p-3) wide: needed takes steps of
    // that width, 8 to 16 of them; 16 is the next level's first class.
    const uint32_t power = highestBit(needed);
    const uint32_t steps = ((needed - 1) >> (power - kClassBits)) + 1;
    return {power - 5 + (steps >> (kClassBits + 1)), steps & (kClasses - 1)};
}

constexpr bool SegmentedHeap::roundedClassesAgree(uint32_t limit)
{
    for (uint32_t needed = kSmallestSegment; needed <= limit; needed += kAlignment) {
        uint32_t rounded = needed; // The rounding as it was written before roundedClassOf().
        if (needed >= 8 * kAlignment) {
            rounded += (uint32_t{1} << (highestBit(needed) - kClassBits)) - 1;
        }
        const SizeClass expected = classOf(rounded);
        const SizeClass actual = roundedClassOf(needed);
        if (expected.level != actual.level || expected.index != actual.index) {
            return false;
        }
    }
    for (uint32_t power = 17; power <= 23; ++power) { // Around every larger power of two.
        for (uint32_t needed = (1u << power) - 64; needed <= (1u << power) + 64; needed += kAlignment) {
            const uint32_t rounded = needed + (uint32_t{1} << (highestBit(needed) - kClassBits)) - 1;
            const SizeClass expected = classOf(rounded);
            const SizeClass actual = roundedClassOf(needed);
            if (expected.level != actual.level || expected.index != actual.index) {
                return false;
            }
        }
    }
    return true;
}

constexpr SegmentedHeap::SizeClass SegmentedHeap::classOf(uint32_t size)
{
    const uint32_t units = static_cast<uint32_t>(size / kAlignment);
    if (units < kClasses) {
        return {0, units};
    }
    const uint32_t power = highestBit(units);
    return {power - kClassBits + 1, (units >> (power - kClassBits)) & (kClasses - 1)};
}

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
    limit_ = size_ - static_cast<uint32_t>(kHeaderBytes);
    salt_ = salt;
    multiplier_ = mixBits(salt ^ 0x9E3779B9u) | 1;
    // One free segment spans the heap.
    setWord(0, size_);
    setWord(size_ - 4, endTag(size_, size_));
    insert(0, size_);
    freeSegments_ = 1;
    freeBytes_ = size_;
    lowWater_ = size_;
    return Status::Ok;
}

Result<void*> SegmentedHeap::allocate(size_t bytes, uint16_t holder)
{
    // One compare passes every request that can fit: not on a corrupted
    // heap (limit_ 0), not 0 bytes (which wraps), and none of the heap's
    // size less a header or more. The rest is told apart here; the few
    // requests of the heap's last 8 bytes go on, and fail in the search.
    if (bytes - 1 >= limit_) [[unlikely]] {
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
    }
    const uint32_t needed = static_cast<uint32_t>(HeapAgent::SegmentBytes(bytes));

    // Round the request up to a class boundary: every segment of the class
    // found then fits, and the first one is taken without a search.
    static_assert(roundedClassesAgree(1u << 17));
    static_assert(classOf(kMaximumHeapBytes & ~uint32_t{7}).level < kLevels, "the largest segment has a class");
    SizeClass found = roundedClassOf(needed);
    if (!findFrom(found)) {
        // The request's own class may still hold a segment that fits: try its first.
        found = classOf(needed);
        if ((levelMaps_[found.level] & (1u << found.index)) == 0) {
            ++failedAllocations_;
            return Status::NoMemory;
        }
        const uint32_t first = heads_[found.level][found.index];
        if (isLink(first) && (word(first) & ~kFlagMask) < needed) {
            ++failedAllocations_;
            return Status::NoMemory;
        }
    }
    const uint32_t current = heads_[found.level][found.index];

    // A listed segment is free, starts its list and fits; its successor in the list points back.
    // checkFree() and its links, each word read once: no previous segment
    // (it starts its list), the next one a link leading back.
    if (!isLink(current)) {
        return fail();
    }
    const uint32_t currentFirst = word(current);
    const uint32_t currentSize = currentFirst & ~kFlagMask;
    if ((currentFirst & kFlagMask) != 0 || currentSize < needed || currentSize > size_ - current
        || word(current + currentSize - 4) != endTag(currentSize, current + currentSize)
        || word(current + 4) != kNone) {
        return fail(); // needed >= kSmallestSegment, so the size is at least that too.
    }
    const uint32_t next = word(current + 8);
    if (next != kNone && (!isLink(next) || word(next + 4) != current)) {
        return fail();
    }
    uint32_t segmentSize = currentSize;
    const uint32_t remainder = currentSize - needed;
    if (remainder >= kSmallestSegment) {
        // Cut the allocation from the start: the remainder keeps the segment's
        // end, so its successor's P flag and the end tag's position stay.
        removeFirst(found, next);
        const uint32_t rest = current + needed;
        setWord(rest, remainder);
        const uint32_t tagOffset = current + currentSize - 4;
        setWord(tagOffset, word(tagOffset) ^ currentSize ^ remainder); // Same end, new size.
        insert(rest, remainder);
        segmentSize = needed;
    } else {
        // The whole segment goes: its successor, allocated, no longer follows a free one.
        const uint32_t after = current + currentSize;
        if (after < size_ && !checkAllocatedFrame(after, kPreviousFreeFlag)) {
            return fail();
        }
        removeFirst(found, next);
        --freeSegments_;
        if (after < size_) {
            setWord(after, word(after) & ~kPreviousFreeFlag); // The seal leaves P out.
        }
    }
    writeAllocated(current, segmentSize, false, holder); // A free segment never follows another free one.
    freeBytes_ -= segmentSize;
    if (freeBytes_ < lowWater_) {
        lowWater_ = freeBytes_;
    }
    ++allocatedSegments_;
    ++allocations_;
    return static_cast<void*>(base_ + current + kHeaderBytes);
}

Status SegmentedHeap::release(void* segment, uint16_t holder, Released* released)
{
    Allocated header{};
    const Result<uint32_t> offset = allocatedOffsetOf(segment, holder, header);
    if (!offset.ok()) {
        return offset.status();
    }
    if (released != nullptr) {
        released->holder = header.holder;
        released->next = HeldLinks::next(base_ + offset.value() + 8);
        released->previous = HeldLinks::previous(base_ + offset.value() + 8);
    }
    return releaseAt(offset.value(), header.size, header.previousFree) != 0 ? Status::Ok : Status::Corrupted;
}

Status SegmentedHeap::transferOffset(void* segment, uint16_t from, uint16_t to, uint32_t& offset,
                                     uint16_t& previous)
{
    Allocated header{};
    const Result<uint32_t> found = allocatedOffsetOf(segment, from, header);
    if (!found.ok()) {
        return found.status();
    }
    writeAllocated(found.value(), header.size, header.previousFree, to);
    offset = found.value();
    previous = header.holder;
    return Status::Ok;
}

bool SegmentedHeap::reclaim(uint32_t offset, uint16_t holder)
{
    Allocated header{};
    if (offset >= limit_ || (offset & kFlagMask) != 0 || !checkAllocated(offset, header) || header.holder != holder) {
        return false;
    }
    return releaseAt(offset, header.size, header.previousFree) != 0;
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
        const uint32_t freedEnd = releaseAt(offset, header.size, header.previousFree);
        if (freedEnd == 0) {
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
    // The largest request that can succeed is the first segment of the
    // highest non-empty class (see allocate()); the counters give the rest.
    uint32_t largest = 0;
    if (levelMap_ != 0) {
        const uint32_t level = highestBit(levelMap_);
        const uint32_t index = highestBit(levelMaps_[level]);
        const uint32_t first = heads_[level][index];
        if (!isLink(first) || !checkFree(first, largest)) {
            return fail();
        }
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
    // Every listed segment was just seen free; lists of freeCount steps in
    // all, each segment in its own class and with consistent back links,
    // visit each free segment exactly once.
    uint32_t steps = 0;
    for (uint32_t level = 0; level < kLevels; ++level) {
        if (((levelMap_ >> level) & 1) != (levelMaps_[level] != 0 ? 1u : 0u)) {
            return fail();
        }
        for (uint32_t index = 0; index < kClasses; ++index) {
            if ((levelMaps_[level] & (1u << index)) == 0) {
                continue;
            }
            uint32_t previous = kNone;
            uint32_t current = heads_[level][index];
            do {
                uint32_t size;
                if (++steps > freeCount || !isLink(current) || !checkFree(current, size)
                    || word(current + 4) != previous) {
                    return fail();
                }
                const SizeClass sizeClass = classOf(size);
                if (sizeClass.level != level || sizeClass.index != index) {
                    return fail();
                }
                previous = current;
                current = word(current + 8);
            } while (current != kNone);
        }
    }
    return steps == freeCount && (levelMap_ >> kLevels) == 0 ? Status::Ok : fail();
}

inline bool SegmentedHeap::findFrom(SizeClass& sizeClass) const
{
    if (sizeClass.level >= kLevels) {
        return false;
    }
    uint32_t classes = levelMaps_[sizeClass.level] & (0xFFu << sizeClass.index);
    if (classes == 0) {
        // Any class of a higher level fits: the lowest one with a segment.
        const uint32_t levels = levelMap_ & (~uint32_t{1} << sizeClass.level);
        if (levels == 0) {
            return false;
        }
        sizeClass.level = static_cast<uint32_t>(__builtin_ctz(levels));
        classes = levelMaps_[sizeClass.level];
    }
    sizeClass.index = static_cast<uint32_t>(__builtin_ctz(classes));
    return true;
}

inline void SegmentedHeap::removeFirst(SizeClass sizeClass, uint32_t next)
{
    heads_[sizeClass.level][sizeClass.index] = next;
    if (next != kNone) {
        setWord(next + 4, kNone);
        return;
    }
    emptied(sizeClass);
}

inline void SegmentedHeap::emptied(SizeClass sizeClass)
{
    const uint32_t classes = levelMaps_[sizeClass.level] & ~(1u << sizeClass.index);
    levelMaps_[sizeClass.level] = static_cast<uint8_t>(classes);
    if (classes == 0) {
        levelMap_ &= ~(1u << sizeClass.level);
    }
}

inline void SegmentedHeap::insert(uint32_t offset, uint32_t size)
{
    const SizeClass sizeClass = classOf(size);
    uint32_t& head = heads_[sizeClass.level][sizeClass.index];
    const uint32_t bit = 1u << sizeClass.index;
    uint32_t next = kNone;
    if ((levelMaps_[sizeClass.level] & bit) != 0) {
        next = head;
        setWord(next + 4, offset);
    } else {
        levelMaps_[sizeClass.level] = static_cast<uint8_t>(levelMaps_[sizeClass.level] | bit);
        levelMap_ |= 1u << sizeClass.level;
    }
    setWord(offset + 4, kNone);
    setWord(offset + 8, next);
    head = offset;
}

inline void SegmentedHeap::unlink(uint32_t offset, SizeClass sizeClass)
{
    const uint32_t previous = word(offset + 4);
    const uint32_t next = word(offset + 8);
    if (next != kNone) {
        setWord(next + 4, previous);
    }
    if (previous != kNone) {
        setWord(previous + 8, next);
        return;
    }
    heads_[sizeClass.level][sizeClass.index] = next;
    if (next == kNone) {
        emptied(sizeClass);
    }
}


inline uint16_t SegmentedHeap::seal(uint32_t offset, uint32_t first, uint16_t holder) const
{
    // Multiplying by the heap's odd multiplier carries every input bit into
    // the top half, which the seal keeps. The multiplier is a variable, so
    // it is one IMUL: a constant would be expanded into a long shift-and-add
    // chain under -mtune=i486. P is left out: a neighbour's allocation or
    // return flips it with one write instead of a new seal. A wrong P is
    // caught by the boundary tag it makes Return read, or by audit(); it
    // cannot make a segment pass for another.
    uint32_t value = (salt_ ^ offset) * multiplier_;
    value = (value ^ (first & ~kPreviousFreeFlag)) * multiplier_;
    value = (value ^ holder) * multiplier_;
    return static_cast<uint16_t>(value >> 16);
}

inline uint32_t SegmentedHeap::endTag(uint32_t size, uint32_t end) const
{
    return size ^ ((salt_ ^ kTagKind ^ end) * multiplier_);
}

inline bool SegmentedHeap::isLink(uint32_t link) const
{
    // Room for a whole smallest segment, so that its links can be read.
    return (link & kFlagMask) == 0 && link <= size_ - kSmallestSegment;
}

inline bool SegmentedHeap::checkFree(uint32_t offset, uint32_t& size) const
{
    const uint32_t first = word(offset);
    size = first & ~kFlagMask;
    // A free segment has no flags: it is not allocated and its predecessor is not free.
    if ((first & kFlagMask) != 0 || size < kSmallestSegment || size > size_ - offset) {
        return false;
    }
    return word(offset + size - 4) == endTag(size, offset + size) && checkLinks(offset);
}

inline bool SegmentedHeap::checkLinks(uint32_t offset) const
{
    const uint32_t previous = word(offset + 4);
    const uint32_t next = word(offset + 8);
    return (previous == kNone || isLink(previous)) && (next == kNone || isLink(next));
}

inline bool SegmentedHeap::checkAllocatedFrame(uint32_t offset, uint32_t previousFreeFlag) const
{
    // Allocate and Return write only a neighbour's P flag, so they check its
    // frame, not its seal: allocated, P as expected, a size that fits.
    const uint32_t first = word(offset);
    const uint32_t size = first & ~kFlagMask;
    return (first & kFlagMask) == (kAllocatedFlag | previousFreeFlag) && size >= kSmallestSegment
           && size <= size_ - offset;
}

inline bool SegmentedHeap::checkAllocated(uint32_t offset, Allocated& header) const
{
    const uint32_t first = word(offset);
    const uint32_t second = word(offset + 4);
    header.size = first & ~kFlagMask;
    header.holder = static_cast<uint16_t>(second);
    header.previousFree = (first & kPreviousFreeFlag) != 0;
    return (first & (kFlagMask & ~kPreviousFreeFlag)) == kAllocatedFlag && header.size >= kSmallestSegment
           && header.size <= size_ - offset && (second >> 16) == seal(offset, first, header.holder);
}

uint8_t* SegmentedHeap::linksIfAllocated(uint32_t offset) const
{
    Allocated header{};
    if (offset >= limit_ || (offset & kFlagMask) != 0 || !checkAllocated(offset, header)) {
        return nullptr;
    }
    return base_ + offset + 8;
}

inline bool SegmentedHeap::checkListed(uint32_t offset, SizeClass sizeClass) const
{
    // checkLinks() and the list neighbours' links back, each word read
    // once: the previous segment on the list (or, for the first, the head
    // of the class's list) and the next one both lead back to this segment.
    const uint32_t previous = word(offset + 4);
    const uint32_t next = word(offset + 8);
    if (previous == kNone) {
        if ((levelMaps_[sizeClass.level] & (1u << sizeClass.index)) == 0
            || heads_[sizeClass.level][sizeClass.index] != offset) {
            return false;
        }
    } else if (!isLink(previous) || word(previous + 8) != offset) {
        return false;
    }
    return next == kNone || (isLink(next) && word(next + 4) == offset);
}

inline void SegmentedHeap::writeAllocated(uint32_t offset, uint32_t size, bool previousFree, uint16_t holder)
{
    const uint32_t first = size | kAllocatedFlag | (previousFree ? kPreviousFreeFlag : 0);
    setWord(offset, first);
    setWord(offset + 4, (static_cast<uint32_t>(seal(offset, first, holder)) << 16) | holder);
}

inline Result<uint32_t> SegmentedHeap::allocatedOffsetOf(void* segment, uint16_t holder, Allocated& header)
{
    const uintptr_t address = reinterpret_cast<uintptr_t>(segment);
    const uintptr_t base = reinterpret_cast<uintptr_t>(base_);
    // A segment's data starts 16 bytes past a multiple of 8 inside the heap:
    // one compare (against limit_, the heap's size less a header, 0 when
    // corrupted; below the heap's start the offset wraps) and one mask
    // accept it; anything else is told apart only then.
    const uintptr_t offset = address - base - kHeaderBytes;
    if (offset >= limit_ || (offset & kFlagMask) != 0) [[unlikely]] {
        if (corrupted_) {
            return Status::Corrupted;
        }
        if (size_ == 0 || address < base || address - base >= size_) {
            return Status::InvalidArgument; // Not this heap's memory: the heap is unharmed.
        }
        return fail(); // A wild pointer into the heap (its first 16 bytes included).
    }
    // A free or merged segment (a double return) or an overwritten header fails here.
    if (!checkAllocated(static_cast<uint32_t>(offset), header)) {
        return fail();
    }
    if (header.holder != holder && header.holder != kSystemHolder) {
        return Status::NotOwner;
    }
    return static_cast<uint32_t>(offset);
}

uint32_t SegmentedHeap::releaseAt(uint32_t offset, uint32_t segmentSize, bool previousFree)
{
    const auto fail = [this] {
        (void)this->fail();
        return uint32_t{0};
    };
    // Check both neighbours before anything is written.
    const uint32_t nextOffset = offset + segmentSize;
    bool mergeNext = false;
    uint32_t nextSize = 0;
    SizeClass nextClass{};
    if (nextOffset < size_) {
        const uint32_t nextFirst = word(nextOffset);
        if ((nextFirst & kAllocatedFlag) == 0) {
            // checkFree() with its links checked together with the list
            // neighbours they lead to, each link read once.
            nextSize = nextFirst & ~kFlagMask;
            if ((nextFirst & kFlagMask) != 0 || nextSize < kSmallestSegment || nextSize > size_ - nextOffset
                || word(nextOffset + nextSize - 4) != endTag(nextSize, nextOffset + nextSize)) {
                return fail();
            }
            nextClass = classOf(nextSize);
            if (!checkListed(nextOffset, nextClass)) {
                return fail();
            }
            mergeNext = true;
        } else if (!checkAllocatedFrame(nextOffset, 0)) {
            return fail();
        }
    }
    uint32_t previousOffset = 0;
    uint32_t previousSize = 0;
    SizeClass previousClass{};
    if (previousFree) {
        if (offset < kSmallestSegment) {
            return fail();
        }
        // The tag ends where this segment starts; unscrambled, it gives the
        // predecessor's size, which its header (no flags) must repeat. That
        // is checkFree() without computing the same scramble twice.
        previousSize = word(offset - 4) ^ endTag(0, offset);
        if (previousSize > offset || previousSize < kSmallestSegment || (previousSize & kFlagMask) != 0) {
            return fail();
        }
        previousOffset = offset - previousSize;
        if (word(previousOffset) != previousSize) {
            return fail();
        }
        previousClass = classOf(previousSize);
        if (!checkListed(previousOffset, previousClass)) {
            return fail();
        }
    }

    // Merge. An obsolete header is cleared so an old pointer to it reads as a double return.
    uint32_t start = offset;
    uint32_t total = segmentSize;
    uint32_t tag;
    if (mergeNext) {
        unlink(nextOffset, nextClass);
        setWord(nextOffset, 0);
        setWord(nextOffset + 4, 0);
        total += nextSize;
        --freeSegments_;
        // The merged segment ends where the successor did: its tag changes size only.
        tag = word(nextOffset + nextSize - 4) ^ nextSize;
    } else {
        tag = endTag(0, nextOffset);
        if (nextOffset < size_) {
            setWord(nextOffset, word(nextOffset) | kPreviousFreeFlag); // The seal leaves P out.
        }
    }
    if (previousFree) {
        unlink(previousOffset, previousClass);
        setWord(offset, 0);
        setWord(offset + 4, 0);
        start = previousOffset;
        total += previousSize;
    } else {
        ++freeSegments_;
    }
    setWord(start, total);
    setWord(start + total - 4, tag ^ total);
    insert(start, total);
    freeBytes_ += segmentSize;
    --allocatedSegments_;
    ++returns_;
    return start + total;
}

Status SegmentedHeap::fail()
{
    corrupted_ = true;
    limit_ = 0; // Allocate's and Return's first test now refuses every call.
    return Status::Corrupted;
}

} // namespace dcos::internal
