// Host tests of the segmented heap algorithm (seed 7.8): header, alignment
// and minimum size, two-level segregated fit, merging on both sides, holders,
// long randomized sequences checked against an independent model of the
// address space (with bad returns that must be refused without a write),
// and detection of corruption.
#include <dcos/internal/SegmentedHeap.hpp>

#include "GuardedArea.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <random>
#include <vector>

namespace {

using dcos::HeapAgent;
using dcos::HeapStatistics;
using dcos::Status;
using dcos::internal::SegmentedHeap;

constexpr uint16_t kTaskA = 3;
constexpr uint16_t kTaskB = 7;

// A segment's header (size and flags, check and holder, two held-list
// links) and the smallest segment: that header and 8 bytes of data.
constexpr size_t kHeader = SegmentedHeap::kHeaderBytes;
constexpr size_t kSmallest = SegmentedHeap::kSmallestSegment;

using Area = dcos_test::GuardedArea;

HeapStatistics statisticsOf(SegmentedHeap& heap)
{
    const dcos::Result<HeapStatistics> statistics = heap.statistics();
    EXPECT_TRUE(statistics.ok());
    return statistics.value();
}

TEST(SegmentedHeapTest, SegmentBytesHasAHeaderAndAnEightByteMinimum)
{
    EXPECT_EQ(HeapAgent::SegmentBytes(1), kHeader + 8);
    EXPECT_EQ(HeapAgent::SegmentBytes(8), kHeader + 8);
    EXPECT_EQ(HeapAgent::SegmentBytes(9), kHeader + 16);
    EXPECT_EQ(HeapAgent::SegmentBytes(100), kHeader + 104);
}

TEST(SegmentedHeapTest, HeldLinksAreFoundOnlyBehindACheckedHeader)
{
    Area area(512);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 5), Status::Ok);
    uint8_t* const data = static_cast<uint8_t*>(heap.allocate(64, kTaskA).value());
    const uint32_t offset = heap.offsetOf(data);
    EXPECT_EQ(heap.linksIfAllocated(offset), data - 8) << "the header's third and fourth words";
    // A header forged inside the data (a size with the allocated flag, as a
    // handle left from a deleted heap might find) is not taken for one.
    const uint32_t forged = 64 | 1;
    std::memcpy(data + 16, &forged, sizeof forged);
    EXPECT_EQ(heap.linksIfAllocated(offset + 16), nullptr);
    EXPECT_EQ(heap.linksIfAllocated(offset + 4), nullptr) << "not a segment's start";
    EXPECT_EQ(heap.linksIfAllocated(offset + 80), nullptr) << "the free rest of the heap";
    EXPECT_EQ(heap.linksIfAllocated(static_cast<uint32_t>(area.size())), nullptr) << "beyond the heap";
    EXPECT_EQ(heap.release(data, kTaskA), Status::Ok);
    EXPECT_EQ(heap.linksIfAllocated(offset), nullptr) << "a returned segment";
}

TEST(SegmentedHeapTest, ALentSegmentComesBackOnlyUnderTheLentTag)
{
    Area area(512);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 5), Status::Ok);
    void* const lent = heap.allocate(40, SegmentedHeap::kLentHolder).value();
    EXPECT_EQ(heap.release(lent, kTaskA), Status::NotOwner);
    EXPECT_EQ(heap.release(lent, SegmentedHeap::kSystemHolder), Status::NotOwner);
    EXPECT_EQ(heap.release(lent, SegmentedHeap::kLentHolder), Status::Ok);
    EXPECT_FALSE(heap.isCorrupted());
}

TEST(SegmentedHeapTest, AFreshHeapIsOneFreeSegment)
{
    Area area(1024);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 1), Status::Ok);
    const HeapStatistics statistics = statisticsOf(heap);
    EXPECT_EQ(statistics.heapBytes, 1024u);
    EXPECT_EQ(statistics.freeBytes, 1024u);
    EXPECT_EQ(statistics.usedBytes, 0u);
    EXPECT_EQ(statistics.freeSegments, 1u);
    EXPECT_EQ(statistics.largestFreeSegment, 1024u - kHeader);
    EXPECT_EQ(heap.audit(), Status::Ok);
}

TEST(SegmentedHeapTest, RefusesBadAreas)
{
    Area area(64);
    SegmentedHeap heap;
    EXPECT_EQ(heap.initialise(nullptr, 64, 1), Status::InvalidArgument);
    EXPECT_EQ(heap.initialise(area.data(), kSmallest - 1, 1), Status::InvalidArgument);
    EXPECT_EQ(heap.initialise(area.data() + 1, kSmallest + 6, 1),
              Status::InvalidArgument); // kSmallest - 1 usable after alignment.
    EXPECT_FALSE(heap.inService());
    ASSERT_EQ(heap.initialise(area.data(), kSmallest, 1), Status::Ok); // One smallest segment.
    EXPECT_EQ(heap.heapBytes(), kSmallest);
    ASSERT_EQ(heap.initialise(area.data() + 3, 61, 1), Status::Ok); // Aligned to +8, 56 bytes.
    EXPECT_EQ(heap.heapBytes(), 56u);
    EXPECT_EQ(heap.initialise(area.data(), SegmentedHeap::kMaximumHeapBytes + 8, 1), Status::InvalidArgument);
    // The largest heap itself is accepted, and its whole span is usable.
    Area largest(SegmentedHeap::kMaximumHeapBytes);
    ASSERT_EQ(heap.initialise(largest.data(), largest.size(), 1), Status::Ok);
    EXPECT_EQ(heap.heapBytes(), HeapAgent::kMaximumHeapBytes);
    EXPECT_EQ(heap.allocate(HeapAgent::kMaximumHeapBytes - kHeader, kTaskA).value(), largest.data() + kHeader);
    EXPECT_EQ(heap.audit(), Status::Ok);
}

TEST(SegmentedHeapTest, SegmentsAreAlignedAndHoldTheRequest)
{
    Area area(4096);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 1), Status::Ok);
    for (size_t bytes : {1u, 3u, 8u, 9u, 17u, 100u, 255u}) {
        const dcos::Result<void*> segment = heap.allocate(bytes, kTaskA);
        ASSERT_TRUE(segment.ok());
        EXPECT_EQ(reinterpret_cast<uintptr_t>(segment.value()) % 8, 0u);
        std::memset(segment.value(), 0x77, bytes);
    }
    EXPECT_EQ(heap.audit(), Status::Ok);
    EXPECT_EQ(heap.allocate(0, kTaskA).status(), Status::InvalidArgument);
    EXPECT_TRUE(area.guardsIntact());
}

TEST(SegmentedHeapTest, OneByteCostsTwentyFourAndATooSmallRemainderIsGivenAway)
{
    Area area(64);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 1), Status::Ok);
    ASSERT_TRUE(heap.allocate(1, kTaskA).ok());
    EXPECT_EQ(statisticsOf(heap).usedBytes, 24u); // A 16-byte header and 8 bytes of data.
    // 40 free; an 8-byte request (24 with header) leaves 16, too small for a
    // segment (the smallest is 24).
    ASSERT_TRUE(heap.allocate(8, kTaskA).ok());
    const HeapStatistics statistics = statisticsOf(heap);
    EXPECT_EQ(statistics.usedBytes, 64u);
    EXPECT_EQ(statistics.freeSegments, 0u);
    EXPECT_EQ(statistics.largestFreeSegment, 0u);
    EXPECT_EQ(heap.allocate(1, kTaskA).status(), Status::NoMemory);
    EXPECT_EQ(heap.allocate(size_t{1} << 40, kTaskA).status(), Status::NoMemory);
    EXPECT_EQ(statisticsOf(heap).failedAllocations, 2u);
    EXPECT_EQ(heap.audit(), Status::Ok);
}

TEST(SegmentedHeapTest, ReturnMergesWithBothNeighbours)
{
    Area area(16 * 64);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 1), Status::Ok);
    void* a = heap.allocate(40, kTaskA).value();
    void* b = heap.allocate(40, kTaskA).value();
    void* c = heap.allocate(40, kTaskA).value();
    void* d = heap.allocate(40, kTaskA).value(); // Keeps c away from the big free remainder.
    EXPECT_EQ(statisticsOf(heap).freeSegments, 1u);
    EXPECT_EQ(heap.release(a, kTaskA), Status::Ok);
    EXPECT_EQ(heap.release(c, kTaskA), Status::Ok);
    EXPECT_EQ(statisticsOf(heap).freeSegments, 3u);
    EXPECT_EQ(heap.release(b, kTaskA), Status::Ok); // Joins a and c.
    HeapStatistics statistics = statisticsOf(heap);
    EXPECT_EQ(statistics.freeSegments, 2u);
    EXPECT_EQ(statistics.allocatedSegments, 1u);
    EXPECT_EQ(heap.audit(), Status::Ok);
    EXPECT_EQ(heap.release(d, kTaskA), Status::Ok); // Joins everything.
    statistics = statisticsOf(heap);
    EXPECT_EQ(statistics.freeSegments, 1u);
    EXPECT_EQ(statistics.largestFreeSegment, area.size() - kHeader);
    EXPECT_EQ(heap.audit(), Status::Ok);
}

TEST(SegmentedHeapTest, AllocationIsCutFromTheStartOfTheChosenSegment)
{
    Area area(1024);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 1), Status::Ok);
    void* first = heap.allocate(16, kTaskA).value();
    void* second = heap.allocate(100, kTaskA).value();
    EXPECT_EQ(first, area.data() + kHeader);
    EXPECT_EQ(second, area.data() + HeapAgent::SegmentBytes(16) + kHeader);
    EXPECT_EQ(heap.audit(), Status::Ok);
}

TEST(SegmentedHeapTest, SmallFreeSegmentsAreNotSearched)
{
    // Many free smallest segments and one large one: the request goes
    // straight to the large one's class, whatever the number of small ones.
    Area area(kSmallest * 2 * 64 + 512);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 1), Status::Ok);
    std::vector<void*> small;
    for (int i = 0; i < 2 * 64; ++i) {
        small.push_back(heap.allocate(8, kTaskA).value());
    }
    for (int i = 0; i < 2 * 64; i += 2) {
        ASSERT_EQ(heap.release(small[static_cast<size_t>(i)], kTaskA), Status::Ok);
    }
    EXPECT_EQ(statisticsOf(heap).freeSegments, 65u);
    uint8_t* large = static_cast<uint8_t*>(heap.allocate(64, kTaskB).value());
    EXPECT_EQ(large, area.data() + kSmallest * 2 * 64 + kHeader);
    // A smallest-segment request takes one of the small ones.
    uint8_t* fits = static_cast<uint8_t*>(heap.allocate(8, kTaskB).value());
    EXPECT_LT(fits, area.data() + kSmallest * 2 * 64);
    EXPECT_EQ(heap.audit(), Status::Ok);
}

TEST(SegmentedHeapTest, TheLargestFreeSegmentReportedIsTheLargestRequestThatSucceeds)
{
    Area area(4096);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 1), Status::Ok);
    // Free segments of 1,000 and 1,016 bytes (one class, [960, 1024)), kept
    // apart by allocated ones, and the remainder allocated.
    const size_t aBytes = 1000 - kHeader;
    const size_t bBytes = 1016 - kHeader;
    void* a = heap.allocate(aBytes, kTaskA).value();
    void* keep1 = heap.allocate(8, kTaskA).value();
    void* b = heap.allocate(bBytes, kTaskA).value();
    void* keep2 = heap.allocate(8, kTaskA).value();
    const size_t rest = statisticsOf(heap).largestFreeSegment;
    void* keep3 = heap.allocate(rest, kTaskA).value();
    ASSERT_NE(keep3, nullptr);
    ASSERT_EQ(heap.release(b, kTaskA), Status::Ok);
    ASSERT_EQ(heap.release(a, kTaskA), Status::Ok); // First in the class list now.
    const HeapStatistics statistics = statisticsOf(heap);
    EXPECT_EQ(statistics.freeSegments, 2u);
    EXPECT_EQ(statistics.largestFreeSegment, aBytes); // The class's first segment.
    // The rounded request for a 1,008-byte segment finds no higher class; its
    // own class's first segment (1,000 bytes) is too small, so it fails, as reported.
    EXPECT_EQ(heap.allocate(aBytes + 1, kTaskB).status(), Status::NoMemory);
    // aBytes fit the first segment of their own class.
    EXPECT_EQ(heap.allocate(aBytes, kTaskB).value(), a);
    EXPECT_EQ(statisticsOf(heap).largestFreeSegment, bBytes);
    EXPECT_EQ(heap.allocate(bBytes, kTaskB).value(), b);
    EXPECT_EQ(statisticsOf(heap).largestFreeSegment, 0u);
    EXPECT_EQ(heap.audit(), Status::Ok);
    (void)keep1;
    (void)keep2;
}

TEST(SegmentedHeapTest, OnlyTheHolderOrAnyoneForSystemSegmentsMayReturn)
{
    Area area(512);
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 1), Status::Ok);
    void* a = heap.allocate(20, kTaskA).value();
    void* system = heap.allocate(20, SegmentedHeap::kSystemHolder).value();
    EXPECT_EQ(heap.release(a, kTaskB), Status::NotOwner);
    EXPECT_EQ(heap.transfer(a, kTaskB, kTaskB), Status::NotOwner);
    EXPECT_EQ(heap.transfer(a, kTaskA, kTaskB), Status::Ok);
    EXPECT_EQ(heap.release(a, kTaskA), Status::NotOwner);
    EXPECT_EQ(heap.release(a, kTaskB), Status::Ok);
    EXPECT_EQ(heap.release(system, kTaskA), Status::Ok);
    EXPECT_FALSE(heap.isCorrupted());
    EXPECT_EQ(heap.audit(), Status::Ok);
}

// An independent model of the address space: the allocated segments the
// test knows of, with the bytes each consumed, from which the free gaps
// follow. Full coalescing means each maximal gap is exactly one free segment.
struct Model {
    struct Segment {
        size_t requested;
        size_t bytes; // Header included; the request's SegmentBytes, or 8 or 16 more when a remainder was too small.
        uint16_t holder;
        uint8_t pattern;
    };
    std::map<uint8_t*, Segment> allocated; // By data address.
};

// The smallest size of the size class of @p bytes: classes are 8 bytes wide
// below 64 bytes, and each power of two above is cut into eight.
size_t classFloor(size_t bytes)
{
    if (bytes < 64) {
        return bytes;
    }
    size_t power = 64;
    while (power * 2 <= bytes) {
        power *= 2;
    }
    const size_t width = power / 8;
    return bytes / width * width;
}

void checkAgainstModel(SegmentedHeap& heap, const Model& model, uint8_t* base, size_t heapBytes)
{
    size_t gaps = 0;
    size_t gapBytes = 0;
    size_t largestGap = 0;
    uint8_t* position = base; // End of the previous segment.
    auto account = [&](uint8_t* nextStart) {
        ASSERT_GE(nextStart, position) << "segments overlap";
        const size_t gap = static_cast<size_t>(nextStart - position);
        if (gap != 0) {
            ASSERT_GE(gap, kSmallest) << "a hole too small to be a segment";
            ++gaps;
            gapBytes += gap;
            largestGap = std::max(largestGap, gap);
        }
    };
    for (const auto& [data, segment] : model.allocated) {
        account(data - kHeader);
        for (size_t i = 0; i < segment.requested; ++i) {
            ASSERT_EQ(data[i], segment.pattern) << "the heap wrote into an allocated segment";
        }
        // A remainder under a smallest segment (0, 8 or 16 bytes) goes with the allocation.
        const size_t requestBytes = HeapAgent::SegmentBytes(segment.requested);
        ASSERT_TRUE(segment.bytes >= requestBytes && segment.bytes - requestBytes < kSmallest
                    && (segment.bytes - requestBytes) % HeapAgent::kAlignment == 0);
        position = data - kHeader + segment.bytes;
    }
    account(base + heapBytes);
    const dcos::Result<HeapStatistics> result = heap.statistics();
    ASSERT_TRUE(result.ok());
    const HeapStatistics& statistics = result.value();
    EXPECT_EQ(statistics.freeSegments, gaps);
    EXPECT_EQ(statistics.freeBytes, gapBytes);
    EXPECT_EQ(statistics.usedBytes + statistics.freeBytes, heapBytes);
    EXPECT_EQ(statistics.allocatedSegments, model.allocated.size());
    // The largest request that can succeed is the first segment of the
    // highest non-empty class: a whole gap, in the largest gap's class.
    if (largestGap == 0) {
        EXPECT_EQ(statistics.largestFreeSegment, 0u);
    } else {
        EXPECT_LE(statistics.largestFreeSegment + kHeader, largestGap);
        EXPECT_EQ(classFloor(statistics.largestFreeSegment + kHeader), classFloor(largestGap));
    }
}

// Tries a return that must be refused, then puts the heap back as it was.
// The refusal must come before any write: the area is byte for byte what it
// was. A refusal that disables the heap (Corrupted) is undone from a copy
// of the heap object, so the sequence can go on.
void expectRefusedWithoutAWrite(SegmentedHeap& heap, Area& area, void* pointer, uint16_t holder, Status expected)
{
    const std::vector<uint8_t> before(area.data(), area.data() + area.size());
    const SegmentedHeap saved = heap;
    ASSERT_EQ(heap.release(pointer, holder), expected);
    ASSERT_TRUE(std::equal(before.begin(), before.end(), area.data())) << "a refused return wrote into the heap";
    ASSERT_EQ(heap.isCorrupted(), expected == Status::Corrupted);
    heap = saved;
}

TEST(SegmentedHeapTest, RandomizedSequencesMatchTheModel)
{
    std::mt19937 random(19870615);
    for (int round = 0; round < 16; ++round) {
        const size_t heapBytes = 512 + 8 * (random() % 1024);
        Area area(heapBytes);
        SegmentedHeap heap;
        ASSERT_EQ(heap.initialise(area.data(), area.size(), static_cast<uint32_t>(random())), Status::Ok);
        Model model;
        uint32_t allocations = 0;
        uint32_t failed = 0;
        uint32_t returns = 0;
        uint32_t lowWater = static_cast<uint32_t>(heapBytes);
        std::vector<uint8_t*> returned; // Data addresses returned before; some are allocated again.
        // Small, medium and occasional large requests, as a real mix would be.
        const size_t maxRequest = round % 4 == 0 ? 24 : round % 4 == 1 ? 200 : round % 4 == 2 ? heapBytes / 3 : 2000;
        for (int step = 0; step < 6000; ++step) {
            const uint16_t holder = static_cast<uint16_t>(random() % 4);
            const unsigned action = random() % 20;
            if (action < 10) {
                const size_t bytes = 1 + random() % maxRequest;
                const HeapStatistics before = heap.statistics().value();
                const uint32_t largestBefore = before.largestFreeSegment;
                const dcos::Result<void*> segment = heap.allocate(bytes, holder);
                // No loss: a request fails exactly when no free segment is large enough.
                if (HeapAgent::SegmentBytes(bytes) - kHeader > largestBefore) {
                    ASSERT_EQ(segment.status(), Status::NoMemory);
                    ++failed;
                } else {
                    ASSERT_TRUE(segment.ok());
                    uint8_t* data = static_cast<uint8_t*>(segment.value());
                    ASSERT_EQ(reinterpret_cast<uintptr_t>(data) % 8, 0u);
                    ASSERT_GE(data, area.data() + kHeader);
                    ASSERT_LE(data + bytes, area.data() + heapBytes);
                    const uint8_t pattern = static_cast<uint8_t>(random());
                    std::memset(data, pattern, bytes);
                    const uint32_t freeAfter = heap.statistics().value().freeBytes;
                    model.allocated[data] = {bytes, before.freeBytes - freeAfter, holder, pattern};
                    ++allocations;
                    lowWater = std::min(lowWater, freeAfter);
                }
            } else if (action < 19 && !model.allocated.empty()) {
                auto it = model.allocated.begin();
                std::advance(it, static_cast<long>(random() % model.allocated.size()));
                const uint16_t other = static_cast<uint16_t>((it->second.holder + 1) % 4);
                ASSERT_EQ(heap.release(it->first, other), Status::NotOwner);
                if (random() % 4 == 0) {
                    ASSERT_EQ(heap.transfer(it->first, it->second.holder, other), Status::Ok);
                    it->second.holder = other;
                }
                ASSERT_EQ(heap.release(it->first, it->second.holder), Status::Ok);
                returned.push_back(it->first);
                model.allocated.erase(it);
                ++returns;
            } else if (action == 19 && random() % 2 == 0) {
                // A bad return: a double return, a pointer inside a segment
                // or misaligned, or one outside the heap.
                const unsigned kind = random() % 4;
                if (kind == 0 && !returned.empty()) {
                    uint8_t* stale = returned[random() % returned.size()];
                    if (model.allocated.count(stale) == 0) {
                        expectRefusedWithoutAWrite(heap, area, stale, holder, Status::Corrupted);
                    }
                } else if (kind == 1 && !model.allocated.empty()) {
                    auto it = model.allocated.begin();
                    std::advance(it, static_cast<long>(random() % model.allocated.size()));
                    const size_t inside = HeapAgent::SegmentBytes(it->second.requested) - kHeader;
                    if (inside > 8) {
                        uint8_t* pointer = it->first + 8 * (1 + random() % ((inside - 8) / 8 + 1));
                        if (pointer < it->first + inside) {
                            expectRefusedWithoutAWrite(heap, area, pointer, it->second.holder, Status::Corrupted);
                        }
                    }
                } else if (kind == 2 && !model.allocated.empty()) {
                    auto it = model.allocated.begin();
                    std::advance(it, static_cast<long>(random() % model.allocated.size()));
                    expectRefusedWithoutAWrite(heap, area, it->first + 1 + random() % 7, it->second.holder,
                                               Status::Corrupted);
                } else if (kind == 3) {
                    uint8_t outside[16];
                    expectRefusedWithoutAWrite(heap, area, outside, holder, Status::InvalidArgument);
                    expectRefusedWithoutAWrite(heap, area, area.data() + heapBytes, holder, Status::InvalidArgument);
                }
            } else if (!model.allocated.empty()) {
                size_t expected = 0;
                for (auto it = model.allocated.begin(); it != model.allocated.end();) {
                    if (it->second.holder == holder) {
                        it = model.allocated.erase(it);
                        ++expected;
                    } else {
                        ++it;
                    }
                }
                ASSERT_EQ(heap.reclaimHeldBy(holder), expected);
                returns += static_cast<uint32_t>(expected);
            }
            checkAgainstModel(heap, model, area.data(), heapBytes);
            if (HasFatalFailure() || HasNonfatalFailure()) {
                FAIL() << "round " << round << " step " << step;
            }
            if (step % 50 == 0) {
                ASSERT_EQ(heap.audit(), Status::Ok);
            }
        }
        ASSERT_EQ(heap.audit(), Status::Ok);
        const HeapStatistics statistics = heap.statistics().value();
        EXPECT_EQ(statistics.allocations, allocations);
        EXPECT_EQ(statistics.failedAllocations, failed);
        EXPECT_EQ(statistics.returns, returns);
        EXPECT_EQ(statistics.lowWaterFreeBytes, lowWater);
        // Everything returned: one free segment again, nothing lost.
        for (const auto& [data, segment] : model.allocated) {
            ASSERT_EQ(heap.release(data, segment.holder), Status::Ok);
        }
        EXPECT_EQ(heap.statistics().value().freeSegments, 1u);
        EXPECT_EQ(heap.statistics().value().largestFreeSegment, heapBytes - kHeader);
        EXPECT_TRUE(area.guardsIntact());
    }
}

// A corrupted heap fails every call.
void expectDisabled(SegmentedHeap& heap, void* someSegment)
{
    EXPECT_TRUE(heap.isCorrupted());
    EXPECT_EQ(heap.allocate(8, kTaskA).status(), Status::Corrupted);
    EXPECT_EQ(heap.release(someSegment, kTaskA), Status::Corrupted);
    EXPECT_EQ(heap.transfer(someSegment, kTaskA, kTaskB), Status::Corrupted);
    EXPECT_EQ(heap.statistics().status(), Status::Corrupted);
    EXPECT_EQ(heap.audit(), Status::Corrupted);
    EXPECT_EQ(heap.reclaimHeldBy(kTaskA), 0u);
}

class SegmentedHeapCorruptionTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        ASSERT_EQ(heap.initialise(area.data(), area.size(), 0xBEEF), Status::Ok);
        for (uint8_t*& segment : segments) {
            segment = static_cast<uint8_t*>(heap.allocate(kDataBytes, kTaskA).value());
        }
        // Segments are cut from the start: segments[0] is lowest, at offset 0,
        // each kSegmentBytes (40) bytes. Free one in the middle.
        ASSERT_EQ(heap.release(segments[2], kTaskA), Status::Ok);
    }

    // The header words of the segment whose data starts at @p data: the
    // segment's start. Allocated: size and flags at +0, check and holder at
    // +4, held-list links at +8 and +12. Free: size at +0, the previous link
    // at +4, the next link at +8, the end tag in the last word.
    static uint8_t* headerOf(uint8_t* data) { return data - kHeader; }
    // The last word of the segment whose data starts at @p data: a free one's end tag.
    static uint8_t* lastWordOf(uint8_t* data) { return headerOf(data) + kSegmentBytes - 4; }

    static constexpr size_t kDataBytes = 24;
    static constexpr size_t kSegmentBytes = HeapAgent::SegmentBytes(kDataBytes);

    Area area{1024};
    SegmentedHeap heap;
    uint8_t* segments[5] = {};
};

TEST_F(SegmentedHeapCorruptionTest, DoubleReturnDisablesTheHeap)
{
    EXPECT_EQ(heap.release(segments[2], kTaskA), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, DoubleReturnOfAMergedSegmentIsDetected)
{
    // segments[3] sits just above segments[2] (free): it merges into it, and
    // its header is cleared, so a second return cannot pass for a live one.
    ASSERT_EQ(heap.release(segments[3], kTaskA), Status::Ok);
    EXPECT_EQ(heap.audit(), Status::Ok);
    EXPECT_EQ(heap.release(segments[3], kTaskA), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, PointersThatAreNotSegmentStartsDisableTheHeap)
{
    EXPECT_EQ(heap.release(segments[0] + 8, kTaskA), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, MisalignedPointerDisablesTheHeap)
{
    EXPECT_EQ(heap.release(segments[0] + 1, kTaskA), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, ForeignPointerIsRefusedAndTheHeapStaysInService)
{
    uint8_t elsewhere[32];
    EXPECT_EQ(heap.release(elsewhere, kTaskA), Status::InvalidArgument);
    EXPECT_EQ(heap.release(area.data() + area.size(), kTaskA), Status::InvalidArgument);
    EXPECT_EQ(heap.release(nullptr, kTaskA), Status::InvalidArgument);
    EXPECT_FALSE(heap.isCorrupted());
    EXPECT_EQ(heap.release(segments[0], kTaskA), Status::Ok);
    EXPECT_EQ(heap.audit(), Status::Ok);
}

// Allocate and Return test one bound first (the heap's size less a header,
// 0 once corrupted) and tell the failures apart after it: each address
// and size at the edges keeps the reason it had with separate tests.
TEST(SegmentedHeapBoundsTest, TheFoldedBoundsKeepEveryReason)
{
    Area area{256};
    SegmentedHeap heap;
    ASSERT_EQ(heap.initialise(area.data(), area.size(), 0x5EED), Status::Ok);
    const size_t size = heap.heapBytes();
    uint8_t* const base = area.data(); // GuardedArea's data is 8-byte aligned.
    // Requests: 0 is a bad argument; above the heap, or too big for its
    // last kHeader bytes, NoMemory, counted; the whole heap less a header fits.
    EXPECT_EQ(heap.allocate(0, kTaskA).status(), Status::InvalidArgument);
    EXPECT_EQ(heap.allocate(size + 1, kTaskA).status(), Status::NoMemory);
    EXPECT_EQ(heap.allocate(size, kTaskA).status(), Status::NoMemory);
    EXPECT_EQ(heap.allocate(size - kHeader + 1, kTaskA).status(), Status::NoMemory);
    EXPECT_EQ(heap.allocate(SIZE_MAX, kTaskA).status(), Status::NoMemory);
    EXPECT_EQ(statisticsOf(heap).failedAllocations, 4u);
    void* whole = heap.allocate(size - kHeader, kTaskA).value();
    EXPECT_EQ(whole, base + kHeader);
    // Addresses: one past the end and the 8 bytes below it, the bytes below
    // the heap, and the heap's first kHeader bytes.
    EXPECT_EQ(heap.release(base + size, kTaskA), Status::InvalidArgument);
    EXPECT_EQ(heap.release(base - 8, kTaskA), Status::InvalidArgument);
    EXPECT_EQ(heap.release(base - 1, kTaskA), Status::InvalidArgument);
    EXPECT_FALSE(heap.isCorrupted());
    EXPECT_EQ(heap.release(base, kTaskA), Status::Corrupted); // Inside the heap, not a segment's data.
    expectDisabled(heap, whole);
    EXPECT_EQ(heap.release(base + size, kTaskA), Status::Corrupted); // Once corrupted, every call.

    SegmentedHeap other;
    ASSERT_EQ(other.initialise(area.data(), area.size(), 0x5EED), Status::Ok);
    void* first = other.allocate(8, kTaskA).value();
    EXPECT_EQ(other.release(base + size - 8, kTaskA), Status::Corrupted); // The last 8 bytes: inside.
    EXPECT_EQ(other.release(first, kTaskA), Status::Corrupted);

    // The last 8 bytes of the heap's first header (its held-list links).
    SegmentedHeap third;
    ASSERT_EQ(third.initialise(area.data(), area.size(), 0x5EED), Status::Ok);
    void* firstOfThird = third.allocate(8, kTaskA).value();
    EXPECT_EQ(third.release(base + kHeader - 8, kTaskA), Status::Corrupted);
    EXPECT_EQ(third.release(firstOfThird, kTaskA), Status::Corrupted);
}

TEST_F(SegmentedHeapCorruptionTest, OverrunIntoTheNextHeaderIsDetectedByBothSegments)
{
    // segments[0] is lowest; writing past its end hits segments[1]'s header
    // (its size and its check and holder).
    std::memset(segments[0], 0x11, kDataBytes + 8);
    EXPECT_EQ(heap.release(segments[0], kTaskA), Status::Corrupted); // Its successor's header fails.
    expectDisabled(heap, segments[1]);
}

TEST_F(SegmentedHeapCorruptionTest, OverwrittenHolderIsCorruptionNotAnotherOwner)
{
    headerOf(segments[0])[4] = static_cast<uint8_t>(kTaskB); // The holder's low byte.
    EXPECT_EQ(heap.release(segments[0], kTaskB), Status::Corrupted);
    expectDisabled(heap, segments[1]);
}

TEST_F(SegmentedHeapCorruptionTest, OverwrittenSizeIsDetected)
{
    headerOf(segments[0])[1] ^= 0x01; // Size + 256.
    EXPECT_EQ(heap.release(segments[0], kTaskA), Status::Corrupted);
    expectDisabled(heap, segments[1]);
}

TEST_F(SegmentedHeapCorruptionTest, WriteAfterReturnIntoTheLinksIsCaughtByAllocate)
{
    std::memset(headerOf(segments[2]) + 8, 0x00, 8); // The free segment's next link and more.
    std::memset(headerOf(segments[2]) + 4, 0x00, 4); // Its back link.
    EXPECT_EQ(heap.allocate(8, kTaskA).status(), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, OverwrittenBoundaryTagIsCaughtWhenTheSuccessorReturns)
{
    std::memset(lastWordOf(segments[2]), 0x33, 4); // Last word of the free segment.
    EXPECT_EQ(heap.release(segments[3], kTaskA), Status::Corrupted); // segments[3] follows it.
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, OverwrittenBoundaryTagIsCaughtByTheAudit)
{
    std::memset(lastWordOf(segments[2]), 0x33, 4);
    EXPECT_EQ(heap.audit(), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, OverwrittenTagOfTheLargestFreeSegmentIsCaughtByTheStatistics)
{
    // The free remainder above segments[4] is the largest; its tag is the area's last word.
    std::memset(area.data() + area.size() - 4, 0x33, 4);
    EXPECT_EQ(heap.statistics().status(), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, FreeListLoopIsCaught)
{
    // Point the free segment's next link at itself: Allocate takes it first
    // from its class list, and its successor's back link does not point back.
    const uint32_t self = static_cast<uint32_t>(headerOf(segments[2]) - area.data());
    std::memcpy(headerOf(segments[2]) + 8, &self, 4);
    EXPECT_EQ(heap.allocate(16, kTaskA).status(), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, FreeListLoopIsCaughtByTheAudit)
{
    const uint32_t self = static_cast<uint32_t>(headerOf(segments[2]) - area.data());
    std::memcpy(headerOf(segments[2]) + 8, &self, 4);
    EXPECT_EQ(heap.audit(), Status::Corrupted);
}

TEST_F(SegmentedHeapCorruptionTest, OverwrittenSizeOfAFreeSegmentIsCaughtByAllocate)
{
    headerOf(segments[2])[1] ^= 0x01; // Size + 256: the end tag no longer matches.
    EXPECT_EQ(heap.allocate(16, kTaskA).status(), Status::Corrupted);
    expectDisabled(heap, segments[0]);
}

TEST_F(SegmentedHeapCorruptionTest, ClearedPreviousFreeFlagIsCaughtByAudit)
{
    headerOf(segments[3])[0] &= static_cast<uint8_t>(~2u); // segments[3] follows the free segment.
    EXPECT_EQ(heap.audit(), Status::Corrupted);
}

TEST_F(SegmentedHeapCorruptionTest, RecoveryStopsAtAnOverwrittenHeader)
{
    std::memset(headerOf(segments[3]), 0x44, kHeader);
    heap.reclaimHeldBy(kTaskA);
    EXPECT_TRUE(heap.isCorrupted());
}

TEST(SegmentedHeapSaltTest, HeadersAreBoundToTheirHeap)
{
    Area first(256);
    Area second(256);
    SegmentedHeap a;
    SegmentedHeap b;
    ASSERT_EQ(a.initialise(first.data(), first.size(), 1), Status::Ok);
    ASSERT_EQ(b.initialise(second.data(), second.size(), 2), Status::Ok);
    void* inA = a.allocate(40, kTaskA).value();
    void* inB = b.allocate(40, kTaskA).value();
    ASSERT_EQ(static_cast<uint8_t*>(inA) - first.data(), static_cast<uint8_t*>(inB) - second.data());
    std::memcpy(static_cast<uint8_t*>(inB) - kHeader, static_cast<uint8_t*>(inA) - kHeader, kHeader);
    EXPECT_EQ(b.release(inB, kTaskA), Status::Corrupted);
}

} // namespace
