#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/StackArena.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <random>

namespace {

using dcos::internal::StackArena;

// The arena is one static area, so every test leaves it as it found it.
class StackArenaTest : public ::testing::Test {
protected:
    void SetUp() override { initialFree_ = StackArena::freeBytes(); }
    void TearDown() override
    {
        EXPECT_EQ(StackArena::freeBytes(), initialFree_);
        EXPECT_EQ(StackArena::largestFreeBlock(), initialFree_) << "the arena is in one piece again";
    }
    size_t initialFree_ = 0;
};

TEST_F(StackArenaTest, BlocksAreAlignedAndRounded)
{
    const auto a = StackArena::allocate(100);
    ASSERT_TRUE(a.ok());
    EXPECT_EQ(reinterpret_cast<uintptr_t>(a.value()) % StackArena::kAlignment, 0u);
    EXPECT_EQ(StackArena::freeBytes(), initialFree_ - 112);
    StackArena::release(a.value(), 100);
}

TEST_F(StackArenaTest, TooLargeARequestIsRefused)
{
    EXPECT_EQ(StackArena::allocate(initialFree_ + 16).status(), dcos::Status::NoMemory);
    const auto all = StackArena::allocate(initialFree_);
    ASSERT_TRUE(all.ok());
    EXPECT_EQ(StackArena::allocate(16).status(), dcos::Status::NoMemory);
    StackArena::release(all.value(), initialFree_);
}

TEST_F(StackArenaTest, RandomUseNeverOverlapsAndCoalescesFully)
{
    std::mt19937 random(2026);
    std::map<uintptr_t, size_t> live; // start -> rounded size
    for (int step = 0; step < 20000; ++step) {
        if (live.empty() || random() % 3 != 0) {
            const size_t size = 2048 + (random() % 64) * 16 + random() % 16;
            const auto block = StackArena::allocate(size);
            if (!block.ok()) {
                EXPECT_EQ(block.status(), dcos::Status::NoMemory);
                EXPECT_LT(StackArena::largestFreeBlock(), size);
                continue;
            }
            const uintptr_t start = reinterpret_cast<uintptr_t>(block.value());
            const size_t rounded = (size + 15) & ~size_t{15};
            // No overlap with any live block.
            const auto after = live.lower_bound(start);
            if (after != live.end()) {
                ASSERT_LE(start + rounded, after->first);
            }
            if (after != live.begin()) {
                const auto before = std::prev(after);
                ASSERT_LE(before->first + before->second, start);
            }
            live[start] = rounded;
        } else {
            auto victim = live.begin();
            std::advance(victim, random() % live.size());
            StackArena::release(reinterpret_cast<uint8_t*>(victim->first), victim->second);
            live.erase(victim);
        }
        size_t used = 0;
        for (const auto& block : live) {
            used += block.second;
        }
        ASSERT_EQ(StackArena::freeBytes() + used, initialFree_) << "no byte lost at step " << step;
    }
    for (const auto& block : live) {
        StackArena::release(reinterpret_cast<uint8_t*>(block.first), block.second);
    }
}

} // namespace
