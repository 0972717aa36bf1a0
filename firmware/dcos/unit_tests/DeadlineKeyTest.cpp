// Host tests for the encoded deadline priority and its tie-break rules (dissertation 7.4.1).
#include <dcos/internal/DeadlineKey.hpp>

#include <gtest/gtest.h>

using dcos::internal::DeadlineKey;

TEST(DeadlineKeyTest, EncodesPriorityInTopFiveBitsAndLatestStartBelow)
{
    EXPECT_EQ(DeadlineKey::encode(0, 0), 0u);
    EXPECT_EQ(DeadlineKey::encode(1, 0), uint64_t{1} << 59);
    EXPECT_EQ(DeadlineKey::encode(31, 5), (uint64_t{31} << 59) | 5);
    const DeadlineKey key = DeadlineKey::make(3, 1000, 500, 200);
    EXPECT_EQ(key.priority(), 3);
    EXPECT_EQ(key.deadline(), 1500u);
    EXPECT_EQ(key.latestStart(), 1300u);
    EXPECT_EQ(key.encoded(), (uint64_t{3} << 59) | 1300);
    EXPECT_EQ(key.deadlinePeriod(), 500u);
    EXPECT_EQ(key.executionPeriod(), 200u);
}

TEST(DeadlineKeyTest, StaticPriorityDominatesLatestStart)
{
    const DeadlineKey urgentButLowPriority = DeadlineKey::make(5, 0, 10, 0);
    const DeadlineKey relaxedButHighPriority = DeadlineKey::make(4, DeadlineKey::kMaxLatestStart - 10, 10, 0);
    EXPECT_TRUE(relaxedButHighPriority.precedes(urgentButLowPriority));
    EXPECT_FALSE(urgentButLowPriority.precedes(relaxedButHighPriority));
}

TEST(DeadlineKeyTest, EarlierLatestStartWinsWithinAPriority)
{
    // Later deadline but much longer execution: it must start sooner.
    const DeadlineKey longJob = DeadlineKey::make(2, 0, 1000, 900);
    const DeadlineKey shortJob = DeadlineKey::make(2, 0, 500, 10);
    EXPECT_TRUE(longJob.precedes(shortJob));
    EXPECT_FALSE(shortJob.precedes(longJob));
}

TEST(DeadlineKeyTest, TieOnKeyBrokenByShorterDeadlinePeriod)
{
    // Both have latest start 1000; b arrived later with a shorter deadline period.
    const DeadlineKey a = DeadlineKey::make(1, 0, 1500, 500);
    const DeadlineKey b = DeadlineKey::make(1, 400, 1000, 400);
    ASSERT_EQ(a.encoded(), b.encoded());
    EXPECT_TRUE(b.precedes(a));
    EXPECT_FALSE(a.precedes(b));
}

TEST(DeadlineKeyTest, TieOnDeadlinePeriodBrokenByShorterExecutionPeriod)
{
    // Same latest start and deadline period: the shorter job arrived earlier.
    const DeadlineKey shortJob = DeadlineKey::make(1, 100, 1000, 100);
    const DeadlineKey longJob = DeadlineKey::make(1, 300, 1000, 300);
    ASSERT_EQ(shortJob.encoded(), longJob.encoded());
    ASSERT_EQ(shortJob.deadlinePeriod(), longJob.deadlinePeriod());
    EXPECT_TRUE(shortJob.precedes(longJob));
    EXPECT_FALSE(longJob.precedes(shortJob));
}

TEST(DeadlineKeyTest, FullTieNeitherPrecedes)
{
    const DeadlineKey a = DeadlineKey::make(6, 50, 100, 10);
    const DeadlineKey b = DeadlineKey::make(6, 50, 100, 10);
    EXPECT_FALSE(a.precedes(b));
    EXPECT_FALSE(b.precedes(a));
}

TEST(DeadlineKeyTest, OverflowAndUnderflowSaturate)
{
    // Execution period longer than the time to the deadline: already late, most urgent.
    const DeadlineKey late = DeadlineKey::make(2, 10, 5, 100);
    EXPECT_EQ(late.latestStart(), 0u);
    EXPECT_EQ(late.priority(), 2);
    // Latest start beyond 59 bits saturates instead of corrupting the priority bits.
    const DeadlineKey far = DeadlineKey::make(2, uint64_t{1} << 62, 0, 0);
    EXPECT_EQ(far.priority(), 2);
    EXPECT_EQ(far.latestStart(), DeadlineKey::kMaxLatestStart);
    // Deadline beyond 2^64 saturates.
    const DeadlineKey huge = DeadlineKey::make(2, UINT64_MAX - 5, 100, 0);
    EXPECT_EQ(huge.deadline(), UINT64_MAX);
    // A priority above 31 never reaches into other bits.
    EXPECT_EQ(DeadlineKey::encode(200, 7), (uint64_t{31} << 59) | 7);
    EXPECT_TRUE(DeadlineKey::make(30, 0, UINT64_MAX, 0).precedes(DeadlineKey::make(31, 0, 0, 0)));
}
