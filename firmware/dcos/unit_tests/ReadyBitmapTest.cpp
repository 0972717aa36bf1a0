// Host tests for the static scheduler's ready bitmap (dissertation Fig. 7.5).
#include <dcos/internal/ReadyBitmap.hpp>

#include <gtest/gtest.h>

using dcos::internal::ReadyBitmap;

TEST(ReadyBitmapTest, EmptyBitmapReportsNone)
{
    ReadyBitmap bitmap;
    EXPECT_TRUE(bitmap.isEmpty());
    EXPECT_EQ(bitmap.highest(), ReadyBitmap::kNone);
}

TEST(ReadyBitmapTest, HighestIsNumericallyLowestSetPriority)
{
    ReadyBitmap bitmap;
    bitmap.set(31);
    EXPECT_EQ(bitmap.highest(), 31);
    bitmap.set(17);
    EXPECT_EQ(bitmap.highest(), 17);
    bitmap.set(0);
    EXPECT_EQ(bitmap.highest(), 0);
    bitmap.clear(0);
    EXPECT_EQ(bitmap.highest(), 17);
    bitmap.clear(17);
    EXPECT_EQ(bitmap.highest(), 31);
    bitmap.clear(31);
    EXPECT_TRUE(bitmap.isEmpty());
}

TEST(ReadyBitmapTest, EveryPriorityMapsToItsOwnBit)
{
    for (uint8_t priority = 0; priority < ReadyBitmap::kLevels; ++priority) {
        ReadyBitmap bitmap;
        bitmap.set(priority);
        EXPECT_EQ(bitmap.bits(), uint32_t{1} << priority);
        EXPECT_TRUE(bitmap.test(priority));
        EXPECT_EQ(bitmap.highest(), priority);
    }
}

TEST(ReadyBitmapTest, SetIsIdempotentAndClearLeavesOthers)
{
    ReadyBitmap bitmap;
    bitmap.set(5);
    bitmap.set(5);
    bitmap.set(9);
    bitmap.clear(5);
    EXPECT_FALSE(bitmap.test(5));
    EXPECT_TRUE(bitmap.test(9));
    EXPECT_EQ(bitmap.highest(), 9);
}

TEST(ReadyBitmapTest, AllPrioritiesDescendInOrder)
{
    ReadyBitmap bitmap;
    for (uint8_t priority = 0; priority < ReadyBitmap::kLevels; ++priority) {
        bitmap.set(priority);
    }
    EXPECT_EQ(bitmap.bits(), 0xFFFFFFFFu);
    for (uint8_t expected = 0; expected < ReadyBitmap::kLevels; ++expected) {
        ASSERT_EQ(bitmap.highest(), expected);
        bitmap.clear(expected);
    }
    EXPECT_TRUE(bitmap.isEmpty());
}

TEST(ReadyBitmapTest, ClearHighestIsClearOfTheHighestOverEveryPattern)
{
    // Random patterns with their highest priority cleared both ways.
    uint32_t state = 0x9E3779B9u;
    for (int round = 0; round < 10000; ++round) {
        state = state * 1664525u + 1013904223u;
        const uint32_t pattern = state | 1u << (state >> 27); // Never empty.
        ReadyBitmap byNumber;
        ReadyBitmap byBits;
        for (uint8_t priority = 0; priority < ReadyBitmap::kLevels; ++priority) {
            if ((pattern >> priority) & 1u) {
                byNumber.set(priority);
                byBits.set(priority);
            }
        }
        byNumber.clear(byNumber.highest());
        byBits.clearHighest();
        ASSERT_EQ(byBits.bits(), byNumber.bits()) << std::hex << pattern;
    }
}
