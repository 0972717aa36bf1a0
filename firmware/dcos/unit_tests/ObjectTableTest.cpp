// Host tests for the static per-type object table (dissertation 6.4).
#include <dcos/internal/ObjectTable.hpp>

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

using dcos::ObjectId;
using dcos::ObjectType;
using dcos::Status;
using dcos::Visibility;
using dcos::internal::ObjectTable;

namespace {

struct Semaphore {
    int count = 0;
};

constexpr uint16_t kNode = 0x0042;
const ObjectId kTaskA(kNode, ObjectType::Task, 1);
const ObjectId kTaskB(kNode, ObjectType::Task, 2);

using SmallTable = ObjectTable<Semaphore, 16>;

ObjectId create(SmallTable& table, const char* name = nullptr, ObjectId owner = kTaskA,
                Visibility visibility = Visibility::Local)
{
    const auto result = table.Create(owner, name, visibility);
    EXPECT_TRUE(result.ok()) << dcos::statusName(result.status());
    return result.value();
}

} // namespace

TEST(ObjectTableTest, EveryTableHandsOutAllTwelveBitIndices)
{
    EXPECT_EQ((ObjectTable<Semaphore, 8>::kIndexCount), 4096u);
    EXPECT_EQ((ObjectTable<Semaphore, 4096>::kIndexCount), 4096u);
}

TEST(ObjectTableTest, StartsWithoutActiveSlots)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    EXPECT_EQ(table.activeCount(), 0u);
    EXPECT_EQ(table.Create(kTaskA, nullptr, Visibility::Local).status(), Status::TableFull);
}

TEST(ObjectTableTest, AddObjectsGrowsInGroupsOfEightUpToCapacity)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    EXPECT_EQ(table.AddObjects(0), Status::InvalidArgument);
    EXPECT_EQ(table.AddObjects(4), Status::InvalidArgument);
    EXPECT_EQ(table.AddObjects(12), Status::InvalidArgument);
    EXPECT_EQ(table.activeCount(), 0u);
    EXPECT_EQ(table.AddObjects(8), Status::Ok);
    EXPECT_EQ(table.activeCount(), 8u);
    EXPECT_EQ(table.AddObjects(16), Status::TableFull);
    EXPECT_EQ(table.activeCount(), 8u);
    EXPECT_EQ(table.AddObjects(8), Status::Ok);
    EXPECT_EQ(table.activeCount(), 16u);
    EXPECT_EQ(table.AddObjects(8), Status::TableFull);
    EXPECT_EQ(table.freeCount(), 16u);
}

TEST(ObjectTableTest, CreateFillsActiveSlotsThenReportsFullUntilGrown)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    std::set<uint32_t> ids;
    for (int i = 0; i < 8; ++i) {
        ids.insert(create(table).raw());
    }
    EXPECT_EQ(ids.size(), 8u);
    EXPECT_EQ(table.usedCount(), 8u);
    EXPECT_EQ(table.Create(kTaskA, nullptr, Visibility::Local).status(), Status::TableFull);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId grown = create(table);
    EXPECT_GE(grown.index(), 8u);
    EXPECT_LT(grown.index(), 16u);
}

TEST(ObjectTableTest, IdsCarryNodeAndTypeAndResolveToDistinctObjects)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId a = create(table);
    const ObjectId b = create(table);
    EXPECT_EQ(a.node(), kNode);
    EXPECT_EQ(a.type(), ObjectType::Semaphore);
    auto ra = table.resolve(a);
    auto rb = table.resolve(b);
    ASSERT_TRUE(ra.ok());
    ASSERT_TRUE(rb.ok());
    EXPECT_NE(ra.value(), rb.value());
    ra.value()->count = 5;
    EXPECT_EQ(table.resolve(a).value()->count, 5);
}

TEST(ObjectTableTest, ForgedIdsAreRejected)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId good = create(table);
    const uint16_t generationZeroIndex = good.index();

    EXPECT_EQ(table.resolve(ObjectId(kNode + 1, ObjectType::Semaphore, good.index())).status(), Status::Remote);
    EXPECT_EQ(table.resolve(ObjectId::null()).status(), Status::InvalidId);
    EXPECT_EQ(table.resolve(ObjectId(kNode, ObjectType::Timer, good.index())).status(), Status::WrongType);
    // Slot 8 is within Capacity but not yet activated by AddObjects.
    EXPECT_EQ(table.resolve(ObjectId(kNode, ObjectType::Semaphore, 8)).status(), Status::InvalidId);
    // A free slot with its current generation was never handed out.
    EXPECT_EQ(table.resolve(ObjectId(kNode, ObjectType::Semaphore, generationZeroIndex + 1)).status(),
              Status::InvalidId);
    EXPECT_TRUE(table.resolve(good).ok());
}

TEST(ObjectTableTest, DeletedIdIsStaleEvenAfterTheSlotIsReused)
{
    ObjectTable<Semaphore, 8> table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    ObjectId ids[8];
    for (ObjectId& id : ids) {
        const auto result = table.Create(kTaskA, nullptr, Visibility::Local);
        ASSERT_TRUE(result.ok());
        id = result.value();
    }
    table.resolve(ids[3]).value()->count = 77;
    ASSERT_EQ(table.Delete(ids[3]), Status::Ok);
    EXPECT_EQ(table.resolve(ids[3]).status(), Status::StaleId);
    EXPECT_EQ(table.Delete(ids[3]), Status::StaleId);

    // The only free slot is the deleted one, so the next Create must reuse it.
    const auto reused = table.Create(kTaskB, nullptr, Visibility::Local);
    ASSERT_TRUE(reused.ok());
    EXPECT_EQ(table.slotNumber(reused.value()), table.slotNumber(ids[3]));
    EXPECT_NE(reused.value(), ids[3]);
    EXPECT_EQ(table.resolve(ids[3]).status(), Status::StaleId);
    ASSERT_TRUE(table.resolve(reused.value()).ok());
    EXPECT_EQ(table.resolve(reused.value()).value()->count, 0) << "a reused slot starts from T{}";
}

TEST(ObjectTableTest, FreedSlotsAreReusedInFifoOrder)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId first = create(table);
    ASSERT_EQ(table.Delete(first), Status::Ok);
    const size_t firstSlot = table.slotNumber(first);
    // Seven never-used slots are queued ahead of the freed one.
    for (int i = 0; i < 7; ++i) {
        EXPECT_NE(table.slotNumber(create(table)), firstSlot);
    }
    EXPECT_EQ(table.slotNumber(create(table)), firstSlot);
}

// The defect this guards against: with a slot's generation in the index
// bits its capacity leaves free, a semaphore id came back after 496
// create/delete cycles (31 free slots of a 256-slot table, 4 generation
// bits). Every index is now handed out before a freed one comes back.
template <size_t Capacity, size_t Active>
void expectStaleIdLastsAsLongAsTwelveBitsAllow()
{
    static ObjectTable<Semaphore, Capacity> table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(Active), Status::Ok);
    // One long-lived object, as the shell's life semaphore is on a node.
    const ObjectId resident = table.Create(kTaskA, nullptr, Visibility::Local).value();
    const ObjectId original = table.Create(kTaskA, nullptr, Visibility::Local).value();
    ObjectId current = original;
    const size_t bound = ObjectTable<Semaphore, Capacity>::kIndexCount - table.usedCount();
    size_t cycle = 1;
    for (; cycle <= bound; ++cycle) {
        ASSERT_EQ(table.Delete(current), Status::Ok);
        current = table.Create(kTaskA, nullptr, Visibility::Local).value();
        ASSERT_NE(current, original) << "cycle " << cycle;
        ASSERT_EQ(table.resolve(original).status(), Status::StaleId) << "cycle " << cycle;
        ASSERT_TRUE(table.resolve(resident).ok());
    }
    // 4096 indices, two live: the original's index is the oldest free one
    // only after every other index was handed out once more.
    EXPECT_EQ(cycle - 1, 4094u);
    ASSERT_EQ(table.Delete(current), Status::Ok);
    current = table.Create(kTaskA, nullptr, Visibility::Local).value();
    EXPECT_EQ(current, original) << "the index comes back after 4096 - 1 other Creates at the earliest";
}

TEST(ObjectTableTest, AStaleIdLastsAsLongAsTwelveBitsAllowInASmallTable)
{
    expectStaleIdLastsAsLongAsTwelveBitsAllow<8, 8>();
}

TEST(ObjectTableTest, AStaleIdLastsAsLongAsTwelveBitsAllowWithFewSlotsActive)
{
    // The semaphore table of the production image: 256 slots, 32 active.
    expectStaleIdLastsAsLongAsTwelveBitsAllow<256, 32>();
}

TEST(ObjectTableTest, AStaleIdLastsAsLongAsTwelveBitsAllowInAFullSizeTable)
{
    expectStaleIdLastsAsLongAsTwelveBitsAllow<4096, 4096>();
}

TEST(ObjectTableTest, FullSizeTableDetectsDeletedAndForgedIds)
{
    static ObjectTable<Semaphore, 4096> table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(4096), Status::Ok);
    EXPECT_EQ(table.AddObjects(8), Status::TableFull);
    const ObjectId id = table.Create(kTaskA, nullptr, Visibility::Local).value();
    ASSERT_EQ(table.Delete(id), Status::Ok);
    EXPECT_EQ(table.resolve(id).status(), Status::StaleId);
    EXPECT_EQ(table.resolve(ObjectId(kNode, ObjectType::Semaphore, 4095)).status(), Status::InvalidId);
}

TEST(ObjectTableTest, EveryLiveObjectHasItsOwnIndexWhenTheTableIsFull)
{
    static ObjectTable<Semaphore, 4096> table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(4096), Status::Ok);
    std::set<uint32_t> ids;
    std::vector<ObjectId> live;
    for (int round = 0; round < 3; ++round) {
        while (table.freeCount() != 0) {
            const ObjectId id = table.Create(kTaskA, nullptr, Visibility::Local).value();
            live.push_back(id);
        }
        EXPECT_EQ(table.Create(kTaskA, nullptr, Visibility::Local).status(), Status::TableFull);
        std::set<uint32_t> distinct;
        for (const ObjectId id : live) {
            ASSERT_TRUE(table.resolve(id).ok());
            distinct.insert(id.raw());
        }
        EXPECT_EQ(distinct.size(), live.size());
        // Free every other object and go round again.
        std::vector<ObjectId> kept;
        for (size_t i = 0; i < live.size(); ++i) {
            if (i % 2 == 0) {
                ASSERT_EQ(table.Delete(live[i]), Status::Ok);
            } else {
                kept.push_back(live[i]);
            }
        }
        live = kept;
    }
}

TEST(ObjectTableTest, CreateValidatesArguments)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    EXPECT_EQ(table.Create(ObjectId(kNode, ObjectType::Timer, 1), nullptr, Visibility::Local).status(),
              Status::InvalidArgument);
    EXPECT_EQ(table.Create(kTaskA, "0123456789abcdef", Visibility::Local).status(), Status::InvalidArgument);
    EXPECT_EQ(table.Create(kTaskA, nullptr, static_cast<Visibility>(3)).status(), Status::InvalidArgument);
    EXPECT_EQ(table.usedCount(), 0u);
    EXPECT_TRUE(table.Create(kTaskA, "0123456789abcde", Visibility::Local).ok());
    EXPECT_TRUE(table.Create(ObjectId::null(), nullptr, Visibility::Local).ok());
}

TEST(ObjectTableTest, NameToObjectFindsByNameAndHonoursVisibility)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId local = create(table, "local", kTaskA, Visibility::Local);
    const ObjectId regional = create(table, "regional", kTaskA, Visibility::Regional);
    const ObjectId global = create(table, "global", kTaskA, Visibility::Global);
    create(table);

    EXPECT_EQ(table.NameToObject("local", Visibility::Local).value(), local);
    EXPECT_EQ(table.NameToObject("regional", Visibility::Local).value(), regional);
    EXPECT_EQ(table.NameToObject("global", Visibility::Local).value(), global);

    EXPECT_EQ(table.NameToObject("local", Visibility::Regional).status(), Status::NotFound);
    EXPECT_EQ(table.NameToObject("regional", Visibility::Regional).value(), regional);
    EXPECT_EQ(table.NameToObject("global", Visibility::Regional).value(), global);

    EXPECT_EQ(table.NameToObject("local", Visibility::Global).status(), Status::NotFound);
    EXPECT_EQ(table.NameToObject("regional", Visibility::Global).status(), Status::NotFound);
    EXPECT_EQ(table.NameToObject("global", Visibility::Global).value(), global);

    EXPECT_EQ(table.NameToObject("glob", Visibility::Local).status(), Status::NotFound);
    EXPECT_EQ(table.NameToObject("globalx", Visibility::Local).status(), Status::NotFound);
    EXPECT_EQ(table.NameToObject("", Visibility::Local).status(), Status::NotFound);
    EXPECT_EQ(table.NameToObject(nullptr, Visibility::Local).status(), Status::NotFound);
    EXPECT_STREQ(table.nameOf(regional).value(), "regional");
    EXPECT_EQ(table.visibilityOf(global).value(), Visibility::Global);

    ASSERT_EQ(table.Delete(global), Status::Ok);
    EXPECT_EQ(table.NameToObject("global", Visibility::Local).status(), Status::NotFound);
}

TEST(ObjectTableTest, NameToObjectMatchesFullLengthNamesExactly)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId longName = create(table, "abcdefghijklmno");
    EXPECT_EQ(table.NameToObject("abcdefghijklmno", Visibility::Local).value(), longName);
    EXPECT_EQ(table.NameToObject("abcdefghijklmnop", Visibility::Local).status(), Status::NotFound);
    EXPECT_EQ(table.NameToObject("abcdefghijklmn", Visibility::Local).status(), Status::NotFound);
}

TEST(ObjectTableTest, XferOwnershipRequiresCurrentOwner)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId id = create(table, nullptr, kTaskA);
    EXPECT_EQ(table.checkOwner(id, kTaskA), Status::Ok);
    EXPECT_EQ(table.checkOwner(id, kTaskB), Status::NotOwner);
    EXPECT_EQ(table.XferOwnership(id, kTaskB, kTaskB), Status::NotOwner);
    EXPECT_EQ(table.XferOwnership(id, kTaskA, ObjectId(kNode, ObjectType::Heap, 1)), Status::InvalidArgument);
    EXPECT_EQ(table.ownerOf(id).value(), kTaskA);
    EXPECT_EQ(table.XferOwnership(id, kTaskA, kTaskB), Status::Ok);
    EXPECT_EQ(table.ownerOf(id).value(), kTaskB);
    EXPECT_EQ(table.checkOwner(id, kTaskA), Status::NotOwner);
    EXPECT_EQ(table.XferOwnership(ObjectId(kNode, ObjectType::Semaphore, 5), kTaskA, kTaskB), Status::InvalidId);
}

TEST(ObjectTableTest, ForEachOwnedByVisitsOnlyThatOwnersObjectsAndAllowsDelete)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(16), Status::Ok);
    std::set<uint32_t> ownedByA;
    for (int i = 0; i < 10; ++i) {
        const ObjectId id = create(table, nullptr, i % 2 == 0 ? kTaskA : kTaskB);
        if (i % 2 == 0) {
            ownedByA.insert(id.raw());
        }
    }
    const ObjectId moved = create(table, nullptr, kTaskB);
    ASSERT_EQ(table.XferOwnership(moved, kTaskB, kTaskA), Status::Ok);
    ownedByA.insert(moved.raw());

    std::set<uint32_t> visited;
    const size_t count = table.forEachOwnedBy(kTaskA, [&](ObjectId id, Semaphore&) {
        visited.insert(id.raw());
        // Resource recovery deletes while it walks.
        EXPECT_EQ(table.Delete(id), Status::Ok);
    });
    EXPECT_EQ(count, ownedByA.size());
    EXPECT_EQ(visited, ownedByA);
    EXPECT_EQ(table.usedCount(), 5u);
    EXPECT_EQ(table.forEachOwnedBy(kTaskA, [](ObjectId, Semaphore&) {}), 0u);
    EXPECT_EQ(table.forEachOwnedBy(kTaskB, [](ObjectId, Semaphore&) {}), 5u);
}

TEST(ObjectTableTest, SetNodeOnlyWhileEmpty)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    EXPECT_EQ(table.setNode(7), Status::Ok);
    const ObjectId id = create(table);
    EXPECT_EQ(id.node(), 7);
    EXPECT_EQ(table.setNode(8), Status::Busy);
    ASSERT_EQ(table.Delete(id), Status::Ok);
    EXPECT_EQ(table.setNode(8), Status::Ok);
}
