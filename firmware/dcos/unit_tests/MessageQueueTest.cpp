// Host tests for a message port's queue (seed 7.9): FIFO, priority and LIFO
// order, checked against a simple model.
#include <dcos/internal/MessageQueue.hpp>

#include <gtest/gtest.h>

#include <deque>
#include <random>
#include <set>
#include <vector>

using dcos::kLifoMostUrgent;
using dcos::PortOrder;
using dcos::internal::MessageBuffer;
using dcos::internal::MessageBufferPool;
using dcos::internal::MessageQueue;

namespace {

// A pool with its own reserve, every buffer active.
struct Fixture {
    explicit Fixture(size_t count) : reserve(count), pool(reserve.data(), count) { (void)pool.AddMsgBufs(count); }

    // Takes a buffer, tags it with value and queues it with priority.
    void send(MessageQueue& queue, uint8_t value, int priority)
    {
        MessageBuffer* buffer = pool.take();
        ASSERT_NE(buffer, nullptr);
        buffer->message.bytes[0] = value;
        queue.post(*buffer, priority);
    }

    // Receives everything, giving the buffers back, and lists the tags.
    std::vector<uint8_t> drain(MessageQueue& queue)
    {
        std::vector<uint8_t> values;
        while (MessageBuffer* buffer = queue.takeFirst()) {
            values.push_back(buffer->message.bytes[0]);
            pool.give(*buffer);
        }
        return values;
    }

    std::vector<MessageBuffer> reserve;
    MessageBufferPool pool;
};

} // namespace

TEST(MessageQueueTest, ValidPrioritiesAreMinus32To31)
{
    EXPECT_TRUE(MessageQueue::isValidPriority(0));
    EXPECT_TRUE(MessageQueue::isValidPriority(31));
    EXPECT_TRUE(MessageQueue::isValidPriority(-1));
    EXPECT_TRUE(MessageQueue::isValidPriority(-31));
    EXPECT_TRUE(MessageQueue::isValidPriority(kLifoMostUrgent));
    EXPECT_FALSE(MessageQueue::isValidPriority(32));
    EXPECT_FALSE(MessageQueue::isValidPriority(-33));
}

TEST(MessageQueueTest, PlacementMapsSignToEndAndMagnitudeToLevel)
{
    EXPECT_EQ(MessageQueue::placementOf(PortOrder::Priority, 7).level, 7);
    EXPECT_FALSE(MessageQueue::placementOf(PortOrder::Priority, 7).lifo);
    EXPECT_EQ(MessageQueue::placementOf(PortOrder::Priority, -7).level, 7);
    EXPECT_TRUE(MessageQueue::placementOf(PortOrder::Priority, -7).lifo);
    EXPECT_EQ(MessageQueue::placementOf(PortOrder::Priority, kLifoMostUrgent).level, 0);
    EXPECT_TRUE(MessageQueue::placementOf(PortOrder::Priority, kLifoMostUrgent).lifo);
    EXPECT_EQ(MessageQueue::placementOf(PortOrder::Fifo, 31).level, 0);
    EXPECT_FALSE(MessageQueue::placementOf(PortOrder::Fifo, 31).lifo);
    EXPECT_EQ(MessageQueue::placementOf(PortOrder::Fifo, -5).level, 0);
    EXPECT_TRUE(MessageQueue::placementOf(PortOrder::Fifo, -5).lifo);
}

TEST(MessageQueueTest, EmptyQueueGivesNothing)
{
    MessageQueue queue;
    EXPECT_TRUE(queue.isEmpty());
    EXPECT_EQ(queue.count(), 0u);
    EXPECT_EQ(queue.takeFirst(), nullptr);
}

TEST(MessageQueueTest, FifoPortKeepsArrivalOrderWhateverThePriority)
{
    Fixture f(8);
    MessageQueue queue(PortOrder::Fifo);
    f.send(queue, 1, 31);
    f.send(queue, 2, 0);
    f.send(queue, 3, 17);
    EXPECT_EQ(queue.count(), 3u);
    EXPECT_EQ(f.drain(queue), (std::vector<uint8_t>{1, 2, 3}));
}

TEST(MessageQueueTest, FifoPortQueuesNegativePrioritiesAtTheHead)
{
    Fixture f(8);
    MessageQueue queue(PortOrder::Fifo);
    f.send(queue, 1, 5);
    f.send(queue, 2, -5);
    f.send(queue, 3, 5);
    f.send(queue, 4, -20);
    EXPECT_EQ(f.drain(queue), (std::vector<uint8_t>{4, 2, 1, 3}));
}

TEST(MessageQueueTest, PriorityPortTakesMostUrgentFirstFifoAmongEquals)
{
    Fixture f(8);
    MessageQueue queue(PortOrder::Priority);
    f.send(queue, 1, 10);
    f.send(queue, 2, 3);
    f.send(queue, 3, 10);
    f.send(queue, 4, 31);
    f.send(queue, 5, 0);
    f.send(queue, 6, 3);
    EXPECT_EQ(queue.levelBits(), (1u << 0) | (1u << 3) | (1u << 10) | (1u << 31));
    EXPECT_EQ(f.drain(queue), (std::vector<uint8_t>{5, 2, 6, 1, 3, 4}));
    EXPECT_EQ(queue.levelBits(), 0u);
}

TEST(MessageQueueTest, NegativePriorityIsLifoAtItsLevel)
{
    Fixture f(8);
    MessageQueue queue(PortOrder::Priority);
    f.send(queue, 1, 4);
    f.send(queue, 2, -4); // Ahead of 1, but still level 4.
    f.send(queue, 3, -4); // Ahead of 2.
    f.send(queue, 4, 2);
    f.send(queue, 5, 4);  // Behind 1.
    f.send(queue, 6, kLifoMostUrgent);
    f.send(queue, 7, 0);
    EXPECT_EQ(f.drain(queue), (std::vector<uint8_t>{6, 7, 4, 3, 2, 1, 5}));
}

TEST(MessageQueueTest, ClearGivesEveryBufferBack)
{
    Fixture f(40);
    MessageQueue queue(PortOrder::Priority);
    for (int i = 0; i < 40; ++i) {
        f.send(queue, static_cast<uint8_t>(i), (i % 2 == 0 ? 1 : -1) * (i % 32));
    }
    EXPECT_EQ(f.pool.freeCount(), 0u);
    queue.clear(f.pool);
    EXPECT_TRUE(queue.isEmpty());
    EXPECT_EQ(queue.count(), 0u);
    EXPECT_EQ(f.pool.freeCount(), 40u);
    // Every buffer can be taken again exactly once.
    std::vector<MessageBuffer*> taken;
    while (MessageBuffer* buffer = f.pool.take()) {
        taken.push_back(buffer);
    }
    EXPECT_EQ(taken.size(), 40u);
    // The queue works after a clear.
    f.pool.give(*taken[0]);
    f.send(queue, 99, 12);
    EXPECT_EQ(f.drain(queue), (std::vector<uint8_t>{99}));
}

TEST(MessageQueueTest, RandomSendsAndReceivesMatchAModel)
{
    std::mt19937 random(20240607);
    for (PortOrder order : {PortOrder::Priority, PortOrder::Fifo}) {
        Fixture f(64);
        MessageQueue queue(order);
        std::deque<uint8_t> model[MessageQueue::kLevels];
        uint8_t next = 0;
        size_t queued = 0;
        for (int step = 0; step < 20000; ++step) {
            const bool sending = queued < 64 && (queued == 0 || random() % 3 != 0);
            if (sending) {
                const int priority = static_cast<int>(random() % 64) - 32;
                const MessageQueue::Placement placement = MessageQueue::placementOf(order, priority);
                f.send(queue, next, priority);
                if (placement.lifo) {
                    model[placement.level].push_front(next);
                } else {
                    model[placement.level].push_back(next);
                }
                ++next;
                ++queued;
            } else {
                MessageBuffer* buffer = queue.takeFirst();
                ASSERT_NE(buffer, nullptr);
                size_t level = 0;
                while (model[level].empty()) {
                    ++level;
                }
                ASSERT_EQ(buffer->message.bytes[0], model[level].front()) << "step " << step;
                model[level].pop_front();
                f.pool.give(*buffer);
                --queued;
            }
            ASSERT_EQ(queue.count(), queued);
            ASSERT_EQ(f.pool.freeCount(), 64 - queued);
        }
    }
}

// Delete's clear() chains the non-empty levels into one list for the pool:
// whatever levels hold messages, every buffer comes back exactly once.
TEST(MessageQueueTest, ClearAfterRandomTrafficGivesEveryBufferBackOnce)
{
    std::mt19937 random(20261125);
    for (int round = 0; round < 200; ++round) {
        const PortOrder order = round % 4 == 0 ? PortOrder::Fifo : PortOrder::Priority;
        Fixture f(48);
        MessageQueue queue(order);
        const int steps = static_cast<int>(random() % 120);
        for (int step = 0; step < steps; ++step) {
            if (f.pool.freeCount() != 0 && random() % 4 != 0) {
                f.send(queue, static_cast<uint8_t>(step), static_cast<int>(random() % 64) - 32);
            } else if (MessageBuffer* buffer = queue.takeFirst()) {
                f.pool.give(*buffer);
            }
        }
        queue.clear(f.pool);
        ASSERT_TRUE(queue.isEmpty());
        ASSERT_EQ(queue.count(), 0u);
        ASSERT_EQ(f.pool.freeCount(), 48u);
        std::set<MessageBuffer*> taken;
        while (MessageBuffer* buffer = f.pool.take()) {
            ASSERT_TRUE(taken.insert(buffer).second) << "a buffer came back twice";
        }
        ASSERT_EQ(taken.size(), 48u);
    }
}
