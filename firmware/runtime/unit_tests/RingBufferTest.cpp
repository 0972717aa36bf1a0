#include <runtime/RingBuffer.hpp>

#include <gtest/gtest.h>

#include <deque>
#include <random>

namespace {

TEST(RingBuffer, FillsToCapacityThenRefuses)
{
    runtime::RingBuffer<char, 8> ring;
    EXPECT_TRUE(ring.empty());
    for (char c = 'a'; c < 'a' + 8; ++c) {
        EXPECT_TRUE(ring.push(c));
    }
    EXPECT_TRUE(ring.full());
    EXPECT_FALSE(ring.push('z'));
    char out = 0;
    for (char c = 'a'; c < 'a' + 8; ++c) {
        ASSERT_TRUE(ring.pop(out));
        EXPECT_EQ(out, c);
    }
    EXPECT_FALSE(ring.pop(out));
}

TEST(RingBuffer, MatchesQueueModelAcrossIndexWrap)
{
    // More than 65536 operations, so the 16-bit free-running indices wrap.
    runtime::RingBuffer<uint32_t, 16> ring;
    std::deque<uint32_t> model;
    std::mt19937 random(99);
    uint32_t next = 0;
    for (int i = 0; i < 300000; ++i) {
        if (random() % 2 == 0) {
            const bool stored = ring.push(next);
            EXPECT_EQ(stored, model.size() < 16);
            if (stored) {
                model.push_back(next);
            }
            ++next;
        } else {
            uint32_t value = 0;
            const bool got = ring.pop(value);
            ASSERT_EQ(got, !model.empty());
            if (got) {
                EXPECT_EQ(value, model.front());
                model.pop_front();
            }
        }
        ASSERT_EQ(ring.size(), model.size());
    }
}

} // namespace
