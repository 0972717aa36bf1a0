// Host tests for the logical object id layout (dissertation Fig. 6.4).
#include <dcos/ObjectId.hpp>

#include <gtest/gtest.h>

using dcos::ObjectId;
using dcos::ObjectType;

TEST(ObjectIdTest, PacksNodeHighTypeMiddleIndexLow)
{
    const ObjectId id(0x1234, ObjectType::Semaphore, 0xABC);
    EXPECT_EQ(id.raw(), 0x1234AABCu);
    EXPECT_EQ(id.node(), 0x1234);
    EXPECT_EQ(id.type(), ObjectType::Semaphore);
    EXPECT_EQ(id.index(), 0xABC);
}

TEST(ObjectIdTest, ExtremeFieldValuesDoNotBleedIntoNeighbours)
{
    const ObjectId maxNode(0xFFFF, ObjectType::None, 0);
    EXPECT_EQ(maxNode.raw(), 0xFFFF0000u);
    const ObjectId maxType(0, ObjectType::Reserved15, 0);
    EXPECT_EQ(maxType.raw(), 0x0000F000u);
    const ObjectId maxIndex(0, ObjectType::None, 0xFFF);
    EXPECT_EQ(maxIndex.raw(), 0x00000FFFu);
}

TEST(ObjectIdTest, IndexBeyondTwelveBitsIsMaskedAndReportedByFits)
{
    const ObjectId id(1, ObjectType::Task, 0x1005);
    EXPECT_EQ(id.index(), 0x005);
    EXPECT_EQ(id.type(), ObjectType::Task);
    EXPECT_TRUE(ObjectId::fits(0xFFF, ObjectType::Task));
    EXPECT_FALSE(ObjectId::fits(0x1000, ObjectType::Task));
}

TEST(ObjectIdTest, RawRoundTripAndNullId)
{
    const ObjectId id = ObjectId::fromRaw(0xBEEF7123u);
    EXPECT_EQ(id.node(), 0xBEEF);
    EXPECT_EQ(id.type(), ObjectType::MessagePort);
    EXPECT_EQ(id.index(), 0x123);
    EXPECT_EQ(ObjectId(id.node(), id.type(), id.index()), id);

    EXPECT_TRUE(ObjectId::null().isNull());
    EXPECT_EQ(ObjectId::null().type(), ObjectType::None);
    EXPECT_FALSE(ObjectId(0, ObjectType::Task, 0).isNull());
    EXPECT_FALSE(id == ObjectId::fromRaw(0xBEEF7124u));
}

TEST(ObjectIdTest, PackingIsUsableAtCompileTime)
{
    static_assert(ObjectId(2, ObjectType::Timer, 7).raw() == 0x00023007u);
    static_assert(ObjectId::fromRaw(0x00023007u).type() == ObjectType::Timer);
    SUCCEED();
}
