#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/StackArena.hpp>

#include <arch_x86/Paging.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <random>

namespace {

using arch_x86::Paging;
using dcos::internal::StackArena;

constexpr size_t kPage = StackArena::kPageSize;

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

TEST_F(StackArenaTest, StacksAreWholePagesAboveAGuardPage)
{
    const auto a = StackArena::allocate(100);
    ASSERT_TRUE(a.ok());
    const uintptr_t base = reinterpret_cast<uintptr_t>(a.value());
    EXPECT_EQ(base % kPage, 0u);
    EXPECT_EQ(StackArena::usableSize(100), kPage);
    EXPECT_EQ(StackArena::freeBytes(), initialFree_ - 2 * kPage) << "one page of stack and one guard page";
    EXPECT_FALSE(Paging::isPresent(base - 1)) << "the page below the stack is its guard";
    EXPECT_FALSE(Paging::isPresent(base - kPage));
    EXPECT_TRUE(Paging::isPresent(base));
    EXPECT_TRUE(StackArena::isGuardOf(a.value(), base - 4));
    EXPECT_FALSE(StackArena::isGuardOf(a.value(), base));
    EXPECT_FALSE(StackArena::isGuardOf(a.value(), base - kPage - 1));
    StackArena::release(a.value(), 100);
    EXPECT_TRUE(Paging::isPresent(base - 1)) << "a released guard is free memory again";
}

TEST_F(StackArenaTest, SizesRoundToPagesWithoutWrapping)
{
    EXPECT_EQ(StackArena::usableSize(1), kPage);
    EXPECT_EQ(StackArena::usableSize(kPage), kPage);
    EXPECT_EQ(StackArena::usableSize(kPage + 1), 2 * kPage);
    EXPECT_EQ(StackArena::blockSize(2048), 2 * kPage);
    EXPECT_EQ(StackArena::blockSize(SIZE_MAX), SIZE_MAX) << "saturates instead of wrapping to a small block";
    EXPECT_EQ(StackArena::allocate(SIZE_MAX).status(), dcos::Status::NoMemory);
    EXPECT_EQ(StackArena::allocate(0).status(), dcos::Status::NoMemory);
}

TEST_F(StackArenaTest, TooLargeARequestIsRefused)
{
    const size_t all = initialFree_ - kPage; // Everything but the guard.
    EXPECT_EQ(StackArena::allocate(all + 1).status(), dcos::Status::NoMemory);
    const auto block = StackArena::allocate(all);
    ASSERT_TRUE(block.ok());
    EXPECT_EQ(StackArena::allocate(16).status(), dcos::Status::NoMemory);
    StackArena::release(block.value(), all);
}

TEST_F(StackArenaTest, RandomUseNeverOverlapsAndCoalescesFully)
{
    std::mt19937 random(2026);
    std::map<uintptr_t, size_t> live; // block start (the guard) -> requested size
    for (int step = 0; step < 20000; ++step) {
        if (live.empty() || random() % 3 != 0) {
            const size_t size = 2048 + (random() % 64) * 256 + random() % 16;
            const auto stack = StackArena::allocate(size);
            if (!stack.ok()) {
                EXPECT_EQ(stack.status(), dcos::Status::NoMemory);
                EXPECT_LT(StackArena::largestFreeBlock(), StackArena::blockSize(size));
                continue;
            }
            const uintptr_t start = reinterpret_cast<uintptr_t>(stack.value()) - kPage;
            const size_t taken = StackArena::blockSize(size);
            ASSERT_FALSE(Paging::isPresent(start));
            // No overlap with any live block, guards included.
            const auto after = live.lower_bound(start);
            if (after != live.end()) {
                ASSERT_LE(start + taken, after->first);
            }
            if (after != live.begin()) {
                const auto before = std::prev(after);
                ASSERT_LE(before->first + StackArena::blockSize(before->second), start);
            }
            live[start] = size;
        } else {
            auto victim = live.begin();
            std::advance(victim, random() % live.size());
            StackArena::release(reinterpret_cast<uint8_t*>(victim->first + kPage), victim->second);
            ASSERT_TRUE(Paging::isPresent(victim->first));
            live.erase(victim);
        }
        size_t used = 0;
        for (const auto& block : live) {
            used += StackArena::blockSize(block.second);
        }
        ASSERT_EQ(StackArena::freeBytes() + used, initialFree_) << "no byte lost at step " << step;
    }
    for (const auto& block : live) {
        StackArena::release(reinterpret_cast<uint8_t*>(block.first + kPage), block.second);
    }
}

} // namespace
