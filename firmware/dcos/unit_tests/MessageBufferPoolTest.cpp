// Host tests for the message-buffer area behind the ports (seed 7.9).
#include <dcos/internal/MessageBufferPool.hpp>

#include <gtest/gtest.h>

#include <set>

using dcos::Status;
using dcos::internal::MessageBuffer;
using dcos::internal::MessageBufferPool;

TEST(MessageBufferPoolTest, NothingIsActiveAtFirst)
{
    MessageBuffer reserve[16];
    MessageBufferPool pool(reserve, 16);
    EXPECT_EQ(pool.capacity(), 16u);
    EXPECT_EQ(pool.activeCount(), 0u);
    EXPECT_EQ(pool.freeCount(), 0u);
    EXPECT_EQ(pool.take(), nullptr);
}

TEST(MessageBufferPoolTest, AddMsgBufsActivatesFromTheReserveOnly)
{
    MessageBuffer reserve[16];
    MessageBufferPool pool(reserve, 16);
    EXPECT_EQ(pool.AddMsgBufs(0), Status::InvalidArgument);
    EXPECT_EQ(pool.AddMsgBufs(10), Status::Ok);
    EXPECT_EQ(pool.activeCount(), 10u);
    EXPECT_EQ(pool.freeCount(), 10u);
    EXPECT_EQ(pool.AddMsgBufs(7), Status::NoMemory);
    EXPECT_EQ(pool.activeCount(), 10u) << "a refused request activates nothing";
    EXPECT_EQ(pool.AddMsgBufs(6), Status::Ok);
    EXPECT_EQ(pool.activeCount(), 16u);
    EXPECT_EQ(pool.AddMsgBufs(1), Status::NoMemory);
}

TEST(MessageBufferPoolTest, EveryActiveBufferIsHandedOutOnceUntilGivenBack)
{
    MessageBuffer reserve[16];
    MessageBufferPool pool(reserve, 16);
    (void)pool.AddMsgBufs(12);
    std::set<MessageBuffer*> taken;
    while (MessageBuffer* buffer = pool.take()) {
        EXPECT_TRUE(buffer >= reserve && buffer < reserve + 12) << "only active buffers";
        EXPECT_TRUE(taken.insert(buffer).second) << "never twice";
    }
    EXPECT_EQ(taken.size(), 12u);
    EXPECT_EQ(pool.freeCount(), 0u);
    pool.give(reserve[3]);
    EXPECT_EQ(pool.freeCount(), 1u);
    EXPECT_EQ(pool.take(), &reserve[3]);
}

TEST(MessageBufferPoolTest, AChainGoesBackWhole)
{
    MessageBuffer reserve[8];
    MessageBufferPool pool(reserve, 8);
    (void)pool.AddMsgBufs(8);
    MessageBuffer* a = pool.take();
    MessageBuffer* b = pool.take();
    MessageBuffer* c = pool.take();
    a->next = b;
    b->next = c;
    pool.giveChain(*a, *c, 3);
    EXPECT_EQ(pool.freeCount(), 8u);
    std::set<MessageBuffer*> taken;
    while (MessageBuffer* buffer = pool.take()) {
        EXPECT_TRUE(taken.insert(buffer).second);
    }
    EXPECT_EQ(taken.size(), 8u);
}
