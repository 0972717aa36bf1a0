// The shared-memory network's ring: order, full and empty, the wrap of its
// indices, and indices overwritten by a fault elsewhere.
#include <bsp/SharedMemoryRing.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <thread>

namespace {

using bsp::SharedMemoryMessage;
using bsp::SharedMemoryRing;

SharedMemoryMessage messageNumbered(uint32_t number)
{
    SharedMemoryMessage message{};
    message.priority = static_cast<uint8_t>(number % 32);
    message.type = 0x11;
    message.length = 8;
    message.destination = 3;
    message.source = 2;
    std::memcpy(message.data, &number, sizeof number);
    return message;
}

uint32_t numberOf(const SharedMemoryMessage& message)
{
    uint32_t number;
    std::memcpy(&number, message.data, sizeof number);
    return number;
}

TEST(SharedMemoryRing, MessagesComeOutInTheOrderTheyWentIn)
{
    auto ring = std::make_unique<SharedMemoryRing>();
    for (uint32_t i = 0; i < 10; ++i) {
        ASSERT_TRUE(ring->push(messageNumbered(i)));
    }
    EXPECT_EQ(ring->waiting(), 10u);
    SharedMemoryMessage out{};
    for (uint32_t i = 0; i < 10; ++i) {
        ASSERT_EQ(ring->pop(out), SharedMemoryRing::Pop::Taken);
        EXPECT_EQ(numberOf(out), i);
        EXPECT_EQ(out.priority, i % 32);
        EXPECT_EQ(out.destination, 3u);
    }
    EXPECT_EQ(ring->pop(out), SharedMemoryRing::Pop::Empty);
}

TEST(SharedMemoryRing, AFullRingRefusesAndKeepsWhatItHolds)
{
    auto ring = std::make_unique<SharedMemoryRing>();
    for (uint32_t i = 0; i < SharedMemoryRing::kSlots; ++i) {
        ASSERT_TRUE(ring->push(messageNumbered(i)));
    }
    EXPECT_FALSE(ring->push(messageNumbered(999)));
    SharedMemoryMessage out{};
    ASSERT_EQ(ring->pop(out), SharedMemoryRing::Pop::Taken);
    EXPECT_EQ(numberOf(out), 0u);
    EXPECT_TRUE(ring->push(messageNumbered(1000)));
    for (uint32_t i = 1; i < SharedMemoryRing::kSlots; ++i) {
        ASSERT_EQ(ring->pop(out), SharedMemoryRing::Pop::Taken);
        EXPECT_EQ(numberOf(out), i);
    }
    ASSERT_EQ(ring->pop(out), SharedMemoryRing::Pop::Taken);
    EXPECT_EQ(numberOf(out), 1000u);
}

TEST(SharedMemoryRing, TheIndicesWrapAtTwoToTheThirtyTwo)
{
    // A ring whose indices are just below the wrap: the bytes of a ring are
    // the indices then the slots, as in shared memory.
    auto ring = std::make_unique<SharedMemoryRing>();
    const uint32_t nearWrap = 0xFFFFFFF0u;
    std::memcpy(reinterpret_cast<uint8_t*>(ring.get()), &nearWrap, sizeof nearWrap);
    std::memcpy(reinterpret_cast<uint8_t*>(ring.get()) + 4, &nearWrap, sizeof nearWrap);
    SharedMemoryMessage out{};
    for (uint32_t i = 0; i < 100; ++i) {
        ASSERT_TRUE(ring->push(messageNumbered(i)));
        ASSERT_EQ(ring->pop(out), SharedMemoryRing::Pop::Taken);
        EXPECT_EQ(numberOf(out), i);
    }
    EXPECT_EQ(ring->waiting(), 0u);
}

TEST(SharedMemoryRing, OverwrittenIndicesAreReportedAndNothingIsTaken)
{
    auto ring = std::make_unique<SharedMemoryRing>();
    ASSERT_TRUE(ring->push(messageNumbered(1)));
    const uint32_t wild = 5000;
    std::memcpy(reinterpret_cast<uint8_t*>(ring.get()), &wild, sizeof wild); // head far past tail
    SharedMemoryMessage out{};
    EXPECT_EQ(ring->pop(out), SharedMemoryRing::Pop::Corrupted);
    EXPECT_EQ(ring->pop(out), SharedMemoryRing::Pop::Corrupted);
    ring->reset();
    EXPECT_EQ(ring->pop(out), SharedMemoryRing::Pop::Empty);
}

TEST(SharedMemoryRing, AWriterAndAReaderOnTwoThreadsLoseAndDuplicateNothing)
{
    auto ring = std::make_unique<SharedMemoryRing>();
    constexpr uint32_t kMessages = 200000;
    std::thread writer([&] {
        for (uint32_t i = 0; i < kMessages;) {
            if (ring->push(messageNumbered(i))) {
                ++i;
            }
        }
    });
    uint32_t expected = 0;
    SharedMemoryMessage out{};
    while (expected < kMessages) {
        const SharedMemoryRing::Pop result = ring->pop(out);
        ASSERT_NE(result, SharedMemoryRing::Pop::Corrupted);
        if (result == SharedMemoryRing::Pop::Taken) {
            ASSERT_EQ(numberOf(out), expected);
            ++expected;
        }
    }
    writer.join();
    EXPECT_EQ(ring->pop(out), SharedMemoryRing::Pop::Empty);
}

} // namespace
