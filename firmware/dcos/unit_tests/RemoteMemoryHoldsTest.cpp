// What other nodes hold of this node's pools and heaps (RemoteMemoryHolds.hpp):
// who may return what, and what a restarted node gets back.
#include <dcos/internal/RemoteMemoryHolds.hpp>

#include <gtest/gtest.h>

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::internal::RemoteMemoryHolds;

const ObjectId kPool = ObjectId::fromRaw(0x00025001);
const ObjectId kHeap = ObjectId::fromRaw(0x00026001);

TEST(RemoteMemoryHoldsTest, OnlyTheNodeThatHoldsABufferMayReturnIt)
{
    RemoteMemoryHolds holds;
    ASSERT_TRUE(holds.add(kPool, 0x1000, 3));
    EXPECT_EQ(holds.check(kPool, 0x1000, 3), Status::Ok);
    EXPECT_EQ(holds.check(kPool, 0x1000, 4), Status::NotOwner) << "another node's task";
    EXPECT_EQ(holds.check(kPool, 0x1004, 3), Status::InvalidArgument) << "not a buffer handed to any node";
    EXPECT_EQ(holds.check(kHeap, 0x1000, 3), Status::InvalidArgument) << "the same address of another area";
    holds.remove(kPool, 0x1000);
    EXPECT_EQ(holds.check(kPool, 0x1000, 3), Status::InvalidArgument) << "returned: a second return is refused";
    EXPECT_EQ(holds.count(), 0u);
}

TEST(RemoteMemoryHoldsTest, AFullTableRefusesAndMakesRoomAsBuffersComeBack)
{
    RemoteMemoryHolds holds;
    for (uint32_t i = 0; i < RemoteMemoryHolds::kCapacity; ++i) {
        ASSERT_TRUE(holds.add(kPool, 0x2000 + 16 * i, 3));
    }
    EXPECT_FALSE(holds.hasRoom());
    EXPECT_FALSE(holds.add(kPool, 0x9000, 3));
    holds.remove(kPool, 0x2000 + 16 * 7);
    EXPECT_TRUE(holds.hasRoom());
    EXPECT_TRUE(holds.add(kHeap, 0x9000, 3));
    EXPECT_EQ(holds.count(), RemoteMemoryHolds::kCapacity);
}

TEST(RemoteMemoryHoldsTest, ARestartedNodeGetsBackEverythingItHeldAndNothingElse)
{
    RemoteMemoryHolds holds;
    ASSERT_TRUE(holds.add(kPool, 0x1000, 3));
    ASSERT_TRUE(holds.add(kHeap, 0x5000, 4));
    ASSERT_TRUE(holds.add(kHeap, 0x6000, 3));
    ASSERT_TRUE(holds.add(kPool, 0x1010, 3));
    RemoteMemoryHolds::Hold out[2];
    // Taken a few at a time, as the remote agent does with a small buffer.
    ASSERT_EQ(holds.takeHoldsOf(3, out, 2), 2u);
    EXPECT_EQ(out[0].address, 0x1000u);
    EXPECT_EQ(out[1].area, kHeap);
    ASSERT_EQ(holds.takeHoldsOf(3, out, 2), 1u);
    EXPECT_EQ(out[0].address, 0x1010u);
    EXPECT_EQ(holds.takeHoldsOf(3, out, 2), 0u);
    EXPECT_EQ(holds.count(), 1u);
    EXPECT_EQ(holds.check(kHeap, 0x5000, 4), Status::Ok) << "node 4's hold stays";
}

} // namespace
