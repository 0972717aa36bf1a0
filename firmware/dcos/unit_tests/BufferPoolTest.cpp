// Host tests of the buffer pool algorithm (seed 7.7): layout, O(1) allocate
// and return, holders, long randomized sequences checked against a simple
// model, and detection of every kind of corruption the seed names.
#include <dcos/internal/BufferPool.hpp>

#include "GuardedArea.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace {

using dcos::BufferPoolAgent;
using dcos::Status;
using dcos::internal::BufferPool;

constexpr uint16_t kTaskA = 3;
constexpr uint16_t kTaskB = 7;

// The pool tests start from a zeroed area.
class Area : public dcos_test::GuardedArea {
public:
    explicit Area(size_t bytes) : GuardedArea(bytes, 0) {}
};

TEST(BufferPoolTest, AreaBytesHoldsExactlyTheRequestedCount)
{
    for (size_t size : {4u, 5u, 8u, 13u, 64u, 100u}) {
        for (size_t count : {1u, 2u, 3u, 7u, 32u, 1000u}) {
            Area area(BufferPoolAgent::AreaBytes(size, count));
            BufferPool pool;
            ASSERT_EQ(pool.initialise(area.data(), area.size(), size, 1), Status::Ok) << size << "x" << count;
            EXPECT_EQ(pool.statistics().totalBuffers, count) << size << "x" << count;
            EXPECT_EQ(pool.statistics().freeBuffers, count);
            EXPECT_EQ(pool.statistics().bufferSize, size);
            // One byte less no longer holds them all.
            BufferPool smaller;
            if (smaller.initialise(area.data(), area.size() - 1, size, 1) == Status::Ok) {
                EXPECT_EQ(smaller.statistics().totalBuffers, count - 1);
            }
        }
    }
}

TEST(BufferPoolTest, BuffersAreAlignedDistinctAndInsideTheArea)
{
    Area area(BufferPoolAgent::AreaBytes(24, 16));
    BufferPool pool;
    ASSERT_EQ(pool.initialise(area.data(), area.size(), 24, 9), Status::Ok);
    std::set<uintptr_t> seen;
    for (int i = 0; i < 16; ++i) {
        const dcos::Result<void*> buffer = pool.allocate(kTaskA);
        ASSERT_TRUE(buffer.ok());
        const uintptr_t address = reinterpret_cast<uintptr_t>(buffer.value());
        EXPECT_EQ(address % 8, 0u);
        EXPECT_GE(address, reinterpret_cast<uintptr_t>(area.data()));
        EXPECT_LE(address + 24, reinterpret_cast<uintptr_t>(area.data()) + area.size());
        EXPECT_TRUE(seen.insert(address).second);
        std::memset(buffer.value(), 0xEE, 24); // The whole buffer is the caller's.
    }
    EXPECT_EQ(pool.audit(), Status::Ok);
    EXPECT_TRUE(area.guardsIntact());
}

TEST(BufferPoolTest, RefusesBadArguments)
{
    Area area(256);
    BufferPool pool;
    EXPECT_EQ(pool.initialise(nullptr, 256, 8, 1), Status::InvalidArgument);
    EXPECT_EQ(pool.initialise(area.data(), area.size(), 3, 1), Status::InvalidArgument);
    EXPECT_EQ(pool.initialise(area.data(), 7, 4, 1), Status::InvalidArgument);
    EXPECT_EQ(pool.initialise(area.data(), area.size(), 300, 1), Status::InvalidArgument);
    EXPECT_FALSE(pool.inService());
    EXPECT_EQ(pool.allocate(kTaskA).status(), Status::NoMemory);
    // An unaligned start is aligned up: fewer buffers fit, none outside the area.
    ASSERT_EQ(pool.initialise(area.data() + 1, 255, 4, 1), Status::Ok);
    EXPECT_GE(reinterpret_cast<uintptr_t>(pool.bufferAt(0)), reinterpret_cast<uintptr_t>(area.data()) + 8);
    // More buffers than 16-bit indices can name.
    std::vector<uint8_t> huge(BufferPoolAgent::AreaBytes(4, BufferPool::kMaximumBuffers + 1) + 8);
    EXPECT_EQ(pool.initialise(huge.data(), huge.size(), 4, 1), Status::InvalidArgument);
    EXPECT_EQ(pool.initialise(huge.data(), BufferPoolAgent::AreaBytes(4, BufferPool::kMaximumBuffers), 4, 1),
              Status::Ok);
    EXPECT_EQ(pool.statistics().totalBuffers, BufferPool::kMaximumBuffers);
}

TEST(BufferPoolTest, EmptyPoolGivesNoMemoryAndCountsIt)
{
    Area area(BufferPoolAgent::AreaBytes(4, 2));
    BufferPool pool;
    ASSERT_EQ(pool.initialise(area.data(), area.size(), 4, 5), Status::Ok);
    void* first = pool.allocate(kTaskA).value();
    void* second = pool.allocate(kTaskA).value();
    EXPECT_NE(first, second);
    EXPECT_EQ(pool.allocate(kTaskA).status(), Status::NoMemory);
    EXPECT_EQ(pool.allocate(kTaskB).status(), Status::NoMemory);
    dcos::BufferPoolStatistics statistics = pool.statistics();
    EXPECT_EQ(statistics.freeBuffers, 0u);
    EXPECT_EQ(statistics.lowWaterMark, 0u);
    EXPECT_EQ(statistics.allocations, 2u);
    EXPECT_EQ(statistics.failedAllocations, 2u);
    EXPECT_EQ(pool.release(second, kTaskA), Status::Ok);
    EXPECT_EQ(pool.allocate(kTaskB).value(), second); // LIFO reuse.
    statistics = pool.statistics();
    EXPECT_EQ(statistics.returns, 1u);
    EXPECT_EQ(statistics.lowWaterMark, 0u);
    EXPECT_FALSE(pool.isCorrupted());
}

TEST(BufferPoolTest, OnlyTheHolderOrAnyoneForSystemBuffersMayReturn)
{
    Area area(BufferPoolAgent::AreaBytes(16, 4));
    BufferPool pool;
    ASSERT_EQ(pool.initialise(area.data(), area.size(), 16, 5), Status::Ok);
    void* a = pool.allocate(kTaskA).value();
    void* system = pool.allocate(BufferPool::kSystemHolder).value();
    EXPECT_EQ(pool.release(a, kTaskB), Status::NotOwner);
    EXPECT_EQ(pool.transfer(a, kTaskB, kTaskB), Status::NotOwner);
    EXPECT_EQ(pool.transfer(a, kTaskA, kTaskB), Status::Ok);
    EXPECT_EQ(pool.release(a, kTaskA), Status::NotOwner);
    EXPECT_EQ(pool.release(a, kTaskB), Status::Ok);
    EXPECT_EQ(pool.release(system, kTaskB), Status::Ok);
    EXPECT_EQ(pool.transfer(pool.allocate(kTaskA).value(), kTaskA, BufferPool::kFreeMark), Status::InvalidArgument);
    EXPECT_EQ(pool.allocate(BufferPool::kFreeMark).status(), Status::InvalidArgument);
    EXPECT_FALSE(pool.isCorrupted());
    EXPECT_EQ(pool.audit(), Status::Ok);
}

TEST(BufferPoolTest, ALentBufferComesBackOnlyUnderTheLentTag)
{
    // Lent to another node's task (RemoteMemoryHolds.hpp): neither a task of
    // this node nor the system may return it, so it cannot be freed twice
    // behind the other node's back.
    Area area(BufferPoolAgent::AreaBytes(16, 2));
    BufferPool pool;
    ASSERT_EQ(pool.initialise(area.data(), area.size(), 16, 5), Status::Ok);
    void* lent = pool.allocate(BufferPool::kLentHolder).value();
    EXPECT_EQ(pool.release(lent, kTaskA), Status::NotOwner);
    EXPECT_EQ(pool.release(lent, BufferPool::kSystemHolder), Status::NotOwner);
    EXPECT_EQ(pool.transfer(lent, kTaskA, kTaskB), Status::NotOwner);
    uint16_t holder = 0;
    ASSERT_TRUE(pool.holderOf(pool.indexOfBuffer(lent), holder));
    EXPECT_EQ(holder, BufferPool::kLentHolder);
    EXPECT_EQ(pool.release(lent, BufferPool::kLentHolder), Status::Ok);
    EXPECT_FALSE(pool.isCorrupted());
    EXPECT_EQ(pool.audit(), Status::Ok);
}

TEST(BufferPoolTest, ReclaimReturnsExactlyTheHoldersBuffers)
{
    Area area(BufferPoolAgent::AreaBytes(8, 10));
    BufferPool pool;
    ASSERT_EQ(pool.initialise(area.data(), area.size(), 8, 5), Status::Ok);
    std::vector<void*> ofA;
    std::vector<void*> ofB;
    for (int i = 0; i < 4; ++i) {
        ofA.push_back(pool.allocate(kTaskA).value());
        ofB.push_back(pool.allocate(kTaskB).value());
    }
    EXPECT_EQ(pool.reclaimHeldBy(kTaskA), 4u);
    EXPECT_EQ(pool.statistics().freeBuffers, 6u);
    EXPECT_EQ(pool.audit(), Status::Ok);
    for (void* buffer : ofB) {
        uint16_t holder;
        const size_t index = (static_cast<uint8_t*>(buffer) - static_cast<uint8_t*>(pool.bufferAt(0))) / 8;
        ASSERT_TRUE(pool.holderOf(index, holder));
        EXPECT_EQ(holder, kTaskB);
    }
    EXPECT_EQ(pool.reclaimHeldBy(kTaskA), 0u);
    EXPECT_EQ(pool.release(ofA[0], kTaskA), Status::Corrupted); // Reclaimed: a later return is a double return.
}

// Long randomized sequences against a model: the set of allocated buffers
// and their holders. Checks no overlap, no loss and the counters.
TEST(BufferPoolTest, RandomizedSequencesMatchTheModel)
{
    std::mt19937 random(20240607);
    for (int round = 0; round < 20; ++round) {
        const size_t size = 4 + random() % 61;
        const size_t count = 1 + random() % 200;
        Area area(BufferPoolAgent::AreaBytes(size, count));
        BufferPool pool;
        ASSERT_EQ(pool.initialise(area.data(), area.size(), size, static_cast<uint32_t>(random())), Status::Ok);
        std::map<uint8_t*, uint16_t> allocated; // Buffer to holder.
        uint32_t allocations = 0;
        uint32_t failed = 0;
        uint32_t returns = 0;
        uint32_t lowWater = static_cast<uint32_t>(count);
        for (int step = 0; step < 5000; ++step) {
            const uint16_t holder = static_cast<uint16_t>(random() % 4);
            const unsigned action = random() % 10;
            if (action < 5) {
                const dcos::Result<void*> buffer = pool.allocate(holder);
                if (allocated.size() == count) {
                    ASSERT_EQ(buffer.status(), Status::NoMemory);
                    ++failed;
                } else {
                    ASSERT_TRUE(buffer.ok());
                    uint8_t* bytes = static_cast<uint8_t*>(buffer.value());
                    // No overlap with any buffer the model says is out.
                    auto next = allocated.lower_bound(bytes);
                    ASSERT_TRUE(next == allocated.end() || next->first >= bytes + size);
                    ASSERT_TRUE(next == allocated.begin() || std::prev(next)->first + size <= bytes);
                    allocated[bytes] = holder;
                    std::memset(bytes, static_cast<int>(step), size); // The caller uses all of it.
                    ++allocations;
                    lowWater = std::min<uint32_t>(lowWater, static_cast<uint32_t>(count - allocated.size()));
                }
            } else if (action < 9 && !allocated.empty()) {
                auto it = allocated.begin();
                std::advance(it, static_cast<long>(random() % allocated.size()));
                const uint16_t other = static_cast<uint16_t>((it->second + 1) % 4);
                ASSERT_EQ(pool.release(it->first, other), Status::NotOwner);
                ASSERT_EQ(pool.release(it->first, it->second), Status::Ok);
                allocated.erase(it);
                ++returns;
            } else if (!allocated.empty()) {
                const size_t reclaimed = pool.reclaimHeldBy(holder);
                size_t expected = 0;
                for (auto it = allocated.begin(); it != allocated.end();) {
                    if (it->second == holder) {
                        it = allocated.erase(it);
                        ++expected;
                    } else {
                        ++it;
                    }
                }
                ASSERT_EQ(reclaimed, expected);
                returns += static_cast<uint32_t>(expected);
            }
            if (step % 97 == 0) {
                ASSERT_EQ(pool.audit(), Status::Ok);
            }
        }
        ASSERT_EQ(pool.audit(), Status::Ok);
        const dcos::BufferPoolStatistics statistics = pool.statistics();
        EXPECT_EQ(statistics.freeBuffers, count - allocated.size());
        EXPECT_EQ(statistics.allocations, allocations);
        EXPECT_EQ(statistics.failedAllocations, failed);
        EXPECT_EQ(statistics.returns, returns);
        EXPECT_EQ(statistics.lowWaterMark, lowWater);
        // No loss: everything returned, the pool hands out every buffer once more.
        for (const auto& [buffer, holder] : allocated) {
            ASSERT_EQ(pool.release(buffer, holder), Status::Ok);
        }
        std::set<void*> all;
        for (size_t i = 0; i < count; ++i) {
            all.insert(pool.allocate(kTaskA).value());
        }
        EXPECT_EQ(all.size(), count);
        EXPECT_EQ(pool.allocate(kTaskA).status(), Status::NoMemory);
        EXPECT_TRUE(area.guardsIntact());
    }
}

// A corrupted pool fails every call and never hands out memory again.
void expectDisabled(BufferPool& pool, void* someBuffer)
{
    EXPECT_TRUE(pool.isCorrupted());
    EXPECT_EQ(pool.allocate(kTaskA).status(), Status::Corrupted);
    EXPECT_EQ(pool.release(someBuffer, kTaskA), Status::Corrupted);
    EXPECT_EQ(pool.transfer(someBuffer, kTaskA, kTaskB), Status::Corrupted);
    EXPECT_EQ(pool.audit(), Status::Corrupted);
    EXPECT_EQ(pool.reclaimHeldBy(kTaskA), 0u);
}

class BufferPoolCorruptionTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        ASSERT_EQ(pool.initialise(area.data(), area.size(), 16, 0x1234), Status::Ok);
        for (void*& buffer : buffers) {
            buffer = pool.allocate(kTaskA).value();
        }
        // Buffers 1 and 3 go back: the free list is 3 -> 1 -> 4 -> 5 -> ... -> 7.
        ASSERT_EQ(pool.release(buffers[1], kTaskA), Status::Ok);
        ASSERT_EQ(pool.release(buffers[3], kTaskA), Status::Ok);
    }

    Area area{BufferPoolAgent::AreaBytes(16, 8)};
    BufferPool pool;
    void* buffers[4] = {};
};

TEST_F(BufferPoolCorruptionTest, DoubleReturnDisablesThePool)
{
    EXPECT_EQ(pool.release(buffers[1], kTaskA), Status::Corrupted);
    expectDisabled(pool, buffers[0]);
}

TEST_F(BufferPoolCorruptionTest, PointerInsideABufferDisablesThePool)
{
    EXPECT_EQ(pool.release(static_cast<uint8_t*>(buffers[0]) + 4, kTaskA), Status::Corrupted);
    expectDisabled(pool, buffers[0]);
}

TEST_F(BufferPoolCorruptionTest, ForeignPointerIsRefusedAndThePoolStaysInService)
{
    uint8_t elsewhere[16];
    EXPECT_EQ(pool.release(elsewhere, kTaskA), Status::InvalidArgument);
    EXPECT_EQ(pool.release(area.data(), kTaskA), Status::InvalidArgument); // The state table is not a buffer.
    EXPECT_EQ(pool.release(nullptr, kTaskA), Status::InvalidArgument);
    EXPECT_FALSE(pool.isCorrupted());
    EXPECT_EQ(pool.release(buffers[0], kTaskA), Status::Ok);
    EXPECT_EQ(pool.audit(), Status::Ok);
}

TEST_F(BufferPoolCorruptionTest, WriteAfterReturnLeavesThePoolIntact)
{
    // The pool keeps nothing inside its buffers: a task that keeps writing
    // into a buffer it returned spoils only its own data.
    std::memset(buffers[3], 0, 16);
    std::memset(buffers[1], 0xFF, 16);
    EXPECT_EQ(pool.audit(), Status::Ok);
    EXPECT_EQ(pool.allocate(kTaskB).value(), buffers[3]);
    EXPECT_EQ(pool.allocate(kTaskB).value(), buffers[1]);
    EXPECT_FALSE(pool.isCorrupted());
}

TEST_F(BufferPoolCorruptionTest, OverwrittenStateWordOfTheHeadIsCaughtByAllocate)
{
    std::memset(area.data() + 3 * 4, 0, 4); // A stray write into the state table.
    EXPECT_EQ(pool.allocate(kTaskB).status(), Status::Corrupted);
    expectDisabled(pool, buffers[0]);
}

TEST_F(BufferPoolCorruptionTest, FreeStateWordCopiedFromAnotherBufferIsDetected)
{
    // Buffer 1's free state word is well formed, but only for buffer 1: the
    // check binds the buffer's index, so it cannot redirect the list from buffer 3.
    std::memcpy(area.data() + 3 * 4, area.data() + 1 * 4, 4);
    EXPECT_EQ(pool.allocate(kTaskB).status(), Status::Corrupted);
    expectDisabled(pool, buffers[0]);
}

TEST_F(BufferPoolCorruptionTest, OverwrittenStateWordIsDetected)
{
    std::memset(area.data() + 0 * 4, 0x5A, 4); // Buffer 0's state word.
    EXPECT_EQ(pool.release(buffers[0], kTaskA), Status::Corrupted);
    expectDisabled(pool, buffers[2]);
}

TEST_F(BufferPoolCorruptionTest, StateWordCopiedFromAnotherBufferIsDetected)
{
    // Buffer 1 is free; copying its state word over buffer 0's must not make
    // buffer 0 look free (the check binds the index).
    std::memcpy(area.data(), area.data() + 4, 4);
    EXPECT_EQ(pool.audit(), Status::Corrupted);
}

TEST_F(BufferPoolCorruptionTest, FreeStateOfTheHeadOverwrittenStopsAllocate)
{
    // Buffer 3 heads the list; make its state word claim "allocated by A".
    uint32_t word;
    std::memcpy(&word, area.data() + 0 * 4, 4); // Buffer 0: allocated by A, but for index 0.
    std::memcpy(area.data() + 3 * 4, &word, 4);
    EXPECT_EQ(pool.allocate(kTaskA).status(), Status::Corrupted);
    expectDisabled(pool, buffers[0]);
}

TEST_F(BufferPoolCorruptionTest, RecoveryStopsAtAnOverwrittenStateWord)
{
    std::memset(area.data() + 2 * 4, 0, 4);
    pool.reclaimHeldBy(kTaskA);
    EXPECT_TRUE(pool.isCorrupted());
}

TEST_F(BufferPoolCorruptionTest, OverwrittenLinkDeeperInTheListIsFound)
{
    std::memset(area.data() + 1 * 4, 0xFF, 4); // Buffer 1's state word: second on the list.
    EXPECT_EQ(pool.audit(), Status::Corrupted);
}

TEST_F(BufferPoolCorruptionTest, OverwrittenLinkDeeperInTheListStopsAllocateWhenReached)
{
    std::memset(area.data() + 1 * 4, 0x00, 4);
    EXPECT_EQ(pool.allocate(kTaskB).value(), buffers[3]); // The head is intact.
    EXPECT_EQ(pool.allocate(kTaskB).status(), Status::Corrupted);
    expectDisabled(pool, buffers[0]);
}

TEST(BufferPoolSaltTest, PoolsWithDifferentSaltsRejectEachOthersWords)
{
    Area first(BufferPoolAgent::AreaBytes(8, 4));
    Area second(BufferPoolAgent::AreaBytes(8, 4));
    BufferPool a;
    BufferPool b;
    ASSERT_EQ(a.initialise(first.data(), first.size(), 8, 1), Status::Ok);
    ASSERT_EQ(b.initialise(second.data(), second.size(), 8, 2), Status::Ok);
    void* buffer = b.allocate(kTaskA).value();
    std::memcpy(second.data(), first.data(), 4 * 4); // b's state table replaced by a's.
    EXPECT_EQ(b.release(buffer, kTaskA), Status::Corrupted);
}

// The fast paths against the model: tryAllocate and tryRelease succeed
// exactly where allocate and release would succeed without the slow path's
// cases (an empty pool, a system buffer returned by a task), and change
// nothing when they decline.
TEST(BufferPoolFastPathTest, RandomizedFastPathsMatchTheModel)
{
    std::mt19937 random(20261130);
    for (int round = 0; round < 40; ++round) {
        const size_t size = 4 + random() % 200;
        const size_t count = 1 + random() % 300;
        Area area(BufferPoolAgent::AreaBytes(size, count) + random() % 8);
        BufferPool pool;
        ASSERT_EQ(pool.initialise(area.data(), area.size(), size, static_cast<uint32_t>(random())), Status::Ok);
        ASSERT_EQ(pool.bufferCount(), count);
        std::map<uint8_t*, uint16_t> allocated;
        uint32_t allocations = 0;
        uint32_t lowWater = static_cast<uint32_t>(count);
        for (int step = 0; step < 4000; ++step) {
            // Holders 0..2 are tasks, 3 stands for the system.
            const unsigned pick = random() % 4;
            const uint16_t holder = pick == 3 ? BufferPool::kSystemHolder : static_cast<uint16_t>(pick);
            const unsigned action = random() % 8;
            // The fast paths take the holder in a word's low half and must
            // ignore its high half (the kernel passes the whole task id).
            const auto word = [&random](uint16_t tag) {
                const uint32_t holderWord = (static_cast<uint32_t>(random()) << 16) | tag;
                return [holderWord] { return holderWord; };
            };
            if (action < 4) {
                void* buffer = pool.tryAllocate(word(holder));
                if (allocated.size() == count) {
                    ASSERT_EQ(buffer, nullptr);
                    ASSERT_EQ(pool.allocate(holder).status(), Status::NoMemory);
                    continue;
                }
                ASSERT_NE(buffer, nullptr);
                uint8_t* bytes = static_cast<uint8_t*>(buffer);
                ASSERT_EQ(allocated.count(bytes), 0u);
                ASSERT_EQ((bytes - static_cast<uint8_t*>(pool.bufferAt(0))) % BufferPoolAgent::Stride(size), 0);
                allocated[bytes] = holder;
                std::memset(bytes, static_cast<int>(step), size);
                ++allocations;
                lowWater = std::min<uint32_t>(lowWater, static_cast<uint32_t>(count - allocated.size()));
            } else if (!allocated.empty()) {
                auto it = allocated.begin();
                std::advance(it, static_cast<long>(random() % allocated.size()));
                // A pointer just inside the buffer, another holder, then the holder itself.
                ASSERT_FALSE(pool.tryRelease(it->first + 1 + random() % (size - 1), word(it->second)));
                const uint16_t other = static_cast<uint16_t>((it->second + 1) % 3);
                ASSERT_FALSE(pool.tryRelease(it->first, word(other)));
                if (it->second == BufferPool::kSystemHolder) {
                    ASSERT_EQ(pool.release(it->first, other), Status::Ok); // Anyone returns system buffers.
                } else {
                    ASSERT_TRUE(pool.tryRelease(it->first, word(it->second)));
                    ASSERT_FALSE(pool.tryRelease(it->first, word(it->second))); // Now free: declined.
                }
                allocated.erase(it);
            }
            ASSERT_EQ(pool.allocatedCount(), allocated.size());
            // The free count is kept as the low-water mark plus the buffers
            // above it: both must match the model after every step.
            const dcos::BufferPoolStatistics now = pool.statistics();
            ASSERT_EQ(now.freeBuffers, count - allocated.size());
            ASSERT_EQ(now.lowWaterMark, lowWater);
            ASSERT_EQ(now.allocations, allocations);
            if (step % 101 == 0) {
                ASSERT_EQ(pool.audit(), Status::Ok);
            }
        }
        ASSERT_EQ(pool.audit(), Status::Ok);
        const dcos::BufferPoolStatistics statistics = pool.statistics();
        EXPECT_EQ(statistics.allocations, allocations);
        EXPECT_EQ(statistics.returns, allocations - allocated.size());
        EXPECT_EQ(statistics.lowWaterMark, lowWater);
        EXPECT_TRUE(area.guardsIntact());
    }
}

// The range and alignment test of Return, a multiplication and a rotation
// instead of a division: for every byte address in and around the pool,
// only the start of a buffer is one; the state table, the padding, the
// inside of every buffer and the bytes on either side of the area are not.
TEST(BufferPoolFastPathTest, OnlyABuffersStartIsABuffer)
{
    for (size_t size = 4; size <= 100; ++size) {
        const size_t count = 1 + size % 7;
        Area area(BufferPoolAgent::AreaBytes(size, count));
        BufferPool pool;
        ASSERT_EQ(pool.initialise(area.data(), area.size(), size, 0x9E3779B9u * static_cast<uint32_t>(size)),
                  Status::Ok);
        std::set<uint8_t*> starts;
        for (size_t i = 0; i < count; ++i) {
            starts.insert(static_cast<uint8_t*>(pool.allocate(kTaskA).value()));
        }
        uint8_t* const begin = area.data();
        for (uint8_t* p = begin - 64; p < begin + area.size() + 64; ++p) {
            if (starts.count(p) == 0) {
                ASSERT_FALSE(pool.tryRelease(p, [] { return uint32_t{kTaskA}; }))
                    << "size " << size << " offset " << (p - begin);
            }
        }
        uint8_t elsewhere[16];
        EXPECT_EQ(pool.release(elsewhere, kTaskA), Status::InvalidArgument);
        EXPECT_EQ(pool.release(begin + area.size(), kTaskA), Status::InvalidArgument);
        for (uint8_t* start : starts) {
            ASSERT_TRUE(pool.tryRelease(start, [] { return uint32_t{kTaskA}; }));
        }
        EXPECT_EQ(pool.audit(), Status::Ok);
        EXPECT_EQ(pool.allocatedCount(), 0u);
    }
}

TEST(BufferPoolFastPathTest, ACorruptedPoolDeclinesEveryFastPath)
{
    Area area(BufferPoolAgent::AreaBytes(8, 4));
    BufferPool pool;
    ASSERT_EQ(pool.initialise(area.data(), area.size(), 8, 77), Status::Ok);
    void* a = pool.allocate(kTaskA).value();
    void* b = pool.allocate(kTaskA).value();
    ASSERT_EQ(pool.release(b, kTaskA), Status::Ok);
    ASSERT_EQ(pool.release(b, kTaskA), Status::Corrupted); // Double return.
    EXPECT_EQ(pool.tryAllocate([] { return uint32_t{kTaskA}; }), nullptr);
    EXPECT_FALSE(pool.tryRelease(a, [] { return uint32_t{kTaskA}; }));
    expectDisabled(pool, a);
}

} // namespace
