// TimedByteQueue: the bytes and their arrival times come out in the order
// the interrupt pushed them, a full queue refuses and counts the newest byte,
// and the indices keep working after they wrap past the capacity.
#include <mbline/TimedByteQueue.hpp>

#include <gtest/gtest.h>

namespace {

using mbline::TimedByte;
using mbline::TimedByteQueue;

TEST(TimedByteQueue, GivesBytesBackInOrderWithTheirTimes)
{
    TimedByteQueue<8> queue;
    EXPECT_TRUE(queue.empty());
    EXPECT_TRUE(queue.push(0x11, 1000));
    EXPECT_TRUE(queue.push(0x22, 2000));
    EXPECT_TRUE(queue.push(0x33, 2000));
    EXPECT_FALSE(queue.empty());
    TimedByte out;
    ASSERT_TRUE(queue.pop(out));
    EXPECT_EQ(out.byte, 0x11);
    EXPECT_EQ(out.timeNs, 1000u);
    ASSERT_TRUE(queue.pop(out));
    EXPECT_EQ(out.byte, 0x22);
    EXPECT_EQ(out.timeNs, 2000u);
    ASSERT_TRUE(queue.pop(out));
    EXPECT_EQ(out.byte, 0x33);
    EXPECT_FALSE(queue.pop(out));
    EXPECT_TRUE(queue.empty());
    EXPECT_EQ(queue.overflows(), 0u);
}

TEST(TimedByteQueue, AFullQueueDropsTheNewestByteAndCountsIt)
{
    TimedByteQueue<4> queue;
    for (uint8_t i = 0; i < 4; ++i) {
        EXPECT_TRUE(queue.push(i, i * 10u));
    }
    EXPECT_FALSE(queue.push(0x99, 99));
    EXPECT_FALSE(queue.push(0x98, 98));
    EXPECT_EQ(queue.overflows(), 2u);
    // The bytes already queued are intact; the refused ones never appear.
    TimedByte out;
    for (uint8_t i = 0; i < 4; ++i) {
        ASSERT_TRUE(queue.pop(out));
        EXPECT_EQ(out.byte, i);
        EXPECT_EQ(out.timeNs, i * 10u);
    }
    EXPECT_FALSE(queue.pop(out));
    // Room again after the consumer caught up.
    EXPECT_TRUE(queue.push(0x55, 500));
    EXPECT_EQ(queue.overflows(), 2u);
}

TEST(TimedByteQueue, KeepsOrderAcrossManyWrapsOfItsIndices)
{
    TimedByteQueue<4> queue;
    TimedByte out;
    uint32_t expected = 0;
    for (uint32_t i = 0; i < 1000; ++i) {
        ASSERT_TRUE(queue.push(static_cast<uint8_t>(i), i));
        if (i % 3 == 2) {
            // The consumer lags by up to three bytes, so the ring is often nearly full.
            while (queue.pop(out)) {
                EXPECT_EQ(out.byte, static_cast<uint8_t>(expected));
                EXPECT_EQ(out.timeNs, expected);
                ++expected;
            }
        }
    }
    while (queue.pop(out)) {
        EXPECT_EQ(out.timeNs, expected);
        ++expected;
    }
    EXPECT_EQ(expected, 1000u);
    EXPECT_EQ(queue.overflows(), 0u);
}

TEST(TimedByteQueue, ClearDropsWhatWaits)
{
    TimedByteQueue<8> queue;
    EXPECT_TRUE(queue.push(1, 1));
    EXPECT_TRUE(queue.push(2, 2));
    queue.clear();
    EXPECT_TRUE(queue.empty());
    TimedByte out;
    EXPECT_FALSE(queue.pop(out));
    EXPECT_TRUE(queue.push(3, 3));
    ASSERT_TRUE(queue.pop(out));
    EXPECT_EQ(out.byte, 3);
    EXPECT_EQ(TimedByteQueue<8>::capacity(), 8u);
}

} // namespace
