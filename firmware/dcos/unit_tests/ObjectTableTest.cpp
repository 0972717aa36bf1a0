// Host tests for the static per-type object table (dissertation 6.4).
#include <dcos/internal/ObjectTable.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <iterator>
#include <map>
#include <memory>
#include <random>
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

// find() compares the whole id with the one kept in the slot its index
// names, 0 (the null id) in a free slot, and refuses the null id: no id
// passes for another, and no id finds a free slot, not the null id nor the
// all-ones id (whose complement is the free slot's 0: an earlier form of the
// key, the id's complement, let it through).
TEST(ObjectTableTest, FindComparesTheWholeIdInOneWord)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    EXPECT_EQ(table.find(ObjectId::null()), nullptr); // Nothing active yet: every slot keeps 0.
    EXPECT_EQ(table.find(ObjectId::fromRaw(0xFFFFFFFFu)), nullptr);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId a = create(table);
    const ObjectId b = create(table);
    ObjectId owner;
    ASSERT_NE(table.find(a, owner), nullptr);
    EXPECT_EQ(owner, kTaskA);
    EXPECT_NE(table.find(a), table.find(b));
    EXPECT_EQ(table.find(ObjectId::null()), nullptr);
    EXPECT_EQ(table.find(ObjectId::fromRaw(0xFFFFFFFFu)), nullptr);
    for (uint32_t bit = 0; bit < 32; ++bit) {
        // Any other node, type or index, one bit away: refused.
        const ObjectId near = ObjectId::fromRaw(a.raw() ^ (1u << bit));
        if (near != b) {
            EXPECT_EQ(table.find(near), nullptr) << "bit " << bit;
        }
    }
    ASSERT_EQ(table.Delete(a), Status::Ok);
    EXPECT_EQ(table.find(a), nullptr);
    EXPECT_NE(table.find(b), nullptr);
    EXPECT_EQ(table.resolve(a).status(), Status::StaleId);
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

TEST(ObjectTableTest, RenameMovesTheNameAndKeepsTheRules)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId id = create(table, "before");
    EXPECT_EQ(table.rename(id, "0123456789abcdef"), Status::InvalidArgument);
    EXPECT_STREQ(table.nameOf(id).value(), "before");
    EXPECT_EQ(table.rename(id, "after"), Status::Ok);
    EXPECT_EQ(table.NameToObject("before", Visibility::Local).status(), Status::NotFound);
    EXPECT_EQ(table.NameToObject("after", Visibility::Local).value(), id);
    EXPECT_EQ(table.rename(id, nullptr), Status::Ok);
    EXPECT_EQ(table.NameToObject("after", Visibility::Local).status(), Status::NotFound);
    EXPECT_STREQ(table.nameOf(id).value(), "");
    ASSERT_EQ(table.Delete(id), Status::Ok);
    EXPECT_EQ(table.rename(id, "again"), Status::StaleId);
}

TEST(ObjectTableTest, DuplicateNamesResolveToTheLowestSlotAndSurviveDeletes)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(16), Status::Ok);
    std::vector<ObjectId> twins;
    for (int i = 0; i < 4; ++i) {
        create(table, "other");
        twins.push_back(create(table, "twin"));
    }
    // Create fills slots in order, so the first twin holds the lowest slot.
    EXPECT_EQ(table.NameToObject("twin", Visibility::Local).value(), twins[0]);
    ASSERT_EQ(table.Delete(twins[0]), Status::Ok);
    EXPECT_EQ(table.NameToObject("twin", Visibility::Local).value(), twins[1]);
    ASSERT_EQ(table.Delete(twins[2]), Status::Ok);
    EXPECT_EQ(table.NameToObject("twin", Visibility::Local).value(), twins[1]);
    ASSERT_EQ(table.Delete(twins[1]), Status::Ok);
    EXPECT_EQ(table.NameToObject("twin", Visibility::Local).value(), twins[3]);
    ASSERT_EQ(table.Delete(twins[3]), Status::Ok);
    EXPECT_EQ(table.NameToObject("twin", Visibility::Local).status(), Status::NotFound);
    EXPECT_TRUE(table.NameToObject("other", Visibility::Local).ok());
}

TEST(ObjectTableTest, SystemObjectsHaveAnOwnerListOfTheirOwn)
{
    SmallTable table(ObjectType::Semaphore, kNode);
    ASSERT_EQ(table.AddObjects(8), Status::Ok);
    const ObjectId system = create(table, nullptr, ObjectId::null());
    create(table, nullptr, kTaskA);
    std::vector<ObjectId> visited;
    EXPECT_EQ(table.forEachOwnedBy(ObjectId::null(), [&](ObjectId id, Semaphore&) { visited.push_back(id); }), 1u);
    EXPECT_EQ(visited, std::vector<ObjectId>{system});
}

namespace {

// Owner keys that make owners share lists, to prove a shared list still
// yields exactly each owner's objects.
struct FewOwnerKeys {
    static constexpr size_t kCount = 3;
    static size_t keyOf(ObjectId owner) { return owner.index() % kCount; }
};

// A reference model of a table: what every name lookup and owner walk must
// answer after any sequence of operations. Slots are modelled too (a FIFO of
// free slots), because duplicate names resolve to the lowest slot.
struct ModelObject {
    ObjectId owner;
    std::string name;
    Visibility visibility;
    size_t slot;
};

template <typename Table>
class ObjectTableModelTest {
public:
    // A recovery empties one owner's lists, so its rate sets how full the
    // table gets: creations outnumber deletions otherwise.
    ObjectTableModelTest(Table& table, uint32_t seed, unsigned recoverPerMille = 50)
        : table_(table), random_(seed), recoverPerMille_(recoverPerMille)
    {
    }

    // Checks every lookup and walk against the model after every
    // checkInterval operations and after the last.
    void run(int operations, int checkInterval = 7)
    {
        for (int step = 0; step < operations; ++step) {
            const unsigned choice = pick(1000);
            if (choice < 30) {
                addObjects();
            } else if (choice < 450) {
                createOne();
            } else if (choice < 700) {
                deleteOne();
            } else if (choice < 800) {
                renameOne();
            } else if (choice < 1000 - recoverPerMille_) {
                transferOne();
            } else {
                recoverOne();
            }
            ASSERT_EQ(table_.usedCount(), objects_.size());
            if (step % checkInterval == 0 || step + 1 == operations) {
                checkEverything();
                if (::testing::Test::HasFailure()) {
                    return;
                }
            }
        }
    }

    size_t maxLive() const { return maxLive_; }

private:
    unsigned pick(unsigned bound) { return static_cast<unsigned>(random_() % bound); }

    template <typename Container>
    const auto& pickFrom(const Container& items)
    {
        return items[pick(static_cast<unsigned>(items.size()))];
    }

    // A few names, so that duplicates and shared buckets are common; the
    // empty name stands for an unnamed object.
    std::string randomName()
    {
        static const std::vector<std::string> names = {"",      "",       "a",    "b",     "sem",  "port",
                                                       "twin",  "twin",   "x1",   "x2",    "x3",   "target",
                                                       "abcdefghijklmno", "node.task", "Z"};
        return pickFrom(names);
    }

    // Owners include the system (null), two tasks that share an index on
    // different nodes, and a few more.
    static const std::vector<ObjectId>& owners()
    {
        static const std::vector<ObjectId> owners = {
            ObjectId::null(),
            ObjectId(kNode, ObjectType::Task, 1),
            ObjectId(kNode, ObjectType::Task, 2),
            ObjectId(kNode, ObjectType::Task, 3),
            ObjectId(kNode, ObjectType::Task, 4095),
            ObjectId(kNode + 1, ObjectType::Task, 1),
        };
        return owners;
    }

    ObjectId randomOwner() { return pickFrom(owners()); }

    Visibility randomVisibility() { return static_cast<Visibility>(pick(3)); }

    ObjectId randomLive()
    {
        auto it = objects_.begin();
        std::advance(it, pick(static_cast<unsigned>(objects_.size())));
        return ObjectId::fromRaw(it->first);
    }

    void addObjects()
    {
        const size_t room = Table::capacity() - table_.activeCount();
        if (room == 0) {
            EXPECT_EQ(table_.AddObjects(Table::kGroupSize), Status::TableFull);
            return;
        }
        const size_t count = Table::kGroupSize * (1 + pick(static_cast<unsigned>(room / Table::kGroupSize)));
        const size_t first = table_.activeCount();
        ASSERT_EQ(table_.AddObjects(count), Status::Ok);
        for (size_t i = 0; i < count; ++i) {
            freeSlots_.push_back(first + i);
        }
    }

    void createOne()
    {
        const ObjectId owner = randomOwner();
        const std::string name = randomName();
        const Visibility visibility = randomVisibility();
        const char* text = name.empty() && pick(2) == 0 ? nullptr : name.c_str();
        const auto result = table_.Create(owner, text, visibility);
        if (freeSlots_.empty()) {
            EXPECT_EQ(result.status(), Status::TableFull);
            return;
        }
        ASSERT_TRUE(result.ok()) << dcos::statusName(result.status());
        const size_t slot = freeSlots_.front();
        freeSlots_.pop_front();
        ASSERT_EQ(table_.slotNumber(result.value()), slot) << "slots are reused oldest freed first";
        ASSERT_EQ(objects_.count(result.value().raw()), 0u);
        objects_[result.value().raw()] = ModelObject{owner, name, visibility, slot};
        maxLive_ = std::max(maxLive_, objects_.size());
    }

    void forget(ObjectId id)
    {
        freeSlots_.push_back(objects_.at(id.raw()).slot);
        objects_.erase(id.raw());
        deleted_.push_back(id);
    }

    void deleteOne()
    {
        if (objects_.empty()) {
            if (!deleted_.empty()) {
                EXPECT_EQ(table_.Delete(pickFrom(deleted_)), Status::StaleId);
            }
            return;
        }
        const ObjectId id = randomLive();
        ASSERT_EQ(table_.Delete(id), Status::Ok);
        forget(id);
        EXPECT_EQ(table_.resolve(id).status(), Status::StaleId);
    }

    void renameOne()
    {
        if (objects_.empty()) {
            return;
        }
        const ObjectId id = randomLive();
        const std::string name = randomName();
        ASSERT_EQ(table_.rename(id, name.c_str()), Status::Ok);
        objects_.at(id.raw()).name = name;
    }

    void transferOne()
    {
        if (objects_.empty()) {
            return;
        }
        const ObjectId id = randomLive();
        ModelObject& object = objects_.at(id.raw());
        const ObjectId newOwner = randomOwner();
        if (pick(5) == 0) {
            // From a task that does not own it: refused, nothing moves.
            const ObjectId wrong = object.owner.isNull() ? ObjectId(kNode, ObjectType::Task, 7) : ObjectId::null();
            EXPECT_EQ(table_.XferOwnership(id, wrong, newOwner), Status::NotOwner);
            return;
        }
        ASSERT_EQ(table_.XferOwnership(id, object.owner, newOwner), Status::Ok);
        object.owner = newOwner;
    }

    // What resource recovery does: delete everything one owner holds, from
    // inside the walk.
    void recoverOne()
    {
        const ObjectId owner = randomOwner();
        std::set<uint32_t> expected;
        for (const auto& [raw, object] : objects_) {
            if (object.owner == owner) {
                expected.insert(raw);
            }
        }
        std::set<uint32_t> visited;
        std::vector<ObjectId> order;
        const size_t count = table_.forEachOwnedBy(owner, [&](ObjectId id, auto&) {
            visited.insert(id.raw());
            order.push_back(id);
            EXPECT_EQ(table_.Delete(id), Status::Ok);
        });
        EXPECT_EQ(count, expected.size());
        ASSERT_EQ(visited, expected);
        for (const ObjectId id : order) {
            forget(id);
        }
    }

    void checkEverything()
    {
        static const std::vector<std::string> probes = {"a",    "b",      "sem",  "port",  "twin", "x1",
                                                        "x2",   "x3",     "target", "abcdefghijklmno",
                                                        "node.task", "Z", "missing", "abcdefghijklmnop", ""};
        for (const std::string& name : probes) {
            for (unsigned scope = 0; scope < 3; ++scope) {
                const Visibility asking = static_cast<Visibility>(scope);
                // The model's answer: the lowest slot among visible objects of that name.
                const ModelObject* best = nullptr;
                uint32_t bestRaw = 0;
                for (const auto& [raw, object] : objects_) {
                    if (!name.empty() && object.name == name && dcos::isVisibleFrom(object.visibility, asking)
                        && (best == nullptr || object.slot < best->slot)) {
                        best = &object;
                        bestRaw = raw;
                    }
                }
                const auto found = table_.NameToObject(name.c_str(), asking);
                if (best == nullptr) {
                    ASSERT_EQ(found.status(), Status::NotFound) << "name '" << name << "' scope " << scope;
                } else {
                    ASSERT_TRUE(found.ok()) << "name '" << name << "' scope " << scope;
                    ASSERT_EQ(found.value().raw(), bestRaw) << "name '" << name << "' scope " << scope;
                }
            }
        }
        // Every owner objects may have, and one that never owns any.
        std::vector<ObjectId> walked = owners();
        walked.push_back(ObjectId(kNode, ObjectType::Task, 7));
        for (const ObjectId owner : walked) {
            std::set<uint32_t> expected;
            for (const auto& [raw, object] : objects_) {
                if (object.owner == owner) {
                    expected.insert(raw);
                }
            }
            std::multiset<uint32_t> visited;
            const size_t count = table_.forEachOwnedBy(owner, [&](ObjectId id, auto&) { visited.insert(id.raw()); });
            ASSERT_EQ(count, expected.size());
            ASSERT_EQ(std::set<uint32_t>(visited.begin(), visited.end()), expected);
            ASSERT_EQ(visited.size(), expected.size()) << "an object was visited twice";
        }
        for (const auto& [raw, object] : objects_) {
            const ObjectId id = ObjectId::fromRaw(raw);
            ASSERT_EQ(table_.ownerOf(id).value(), object.owner);
            ASSERT_EQ(std::string(table_.nameOf(id).value()), object.name);
            ASSERT_EQ(table_.slotNumber(id), object.slot);
            // The fast paths' inline lookup finds what resolve finds, with the owner.
            ObjectId owner;
            ASSERT_EQ(table_.find(id), table_.resolve(id).value());
            ASSERT_EQ(table_.find(id, owner), table_.resolve(id).value());
            ASSERT_EQ(owner, object.owner);
        }
        // And misses wherever resolve fails: deleted ids, ids never handed
        // out, and ids of another type or node whose index is live.
        std::vector<ObjectId> misses(deleted_.begin(), deleted_.end());
        for (unsigned i = 0; i < 16; ++i) {
            const uint16_t index = static_cast<uint16_t>(pick(ObjectId::kMaxIndex + 1));
            misses.push_back(ObjectId(kNode, ObjectType::Semaphore, index));
            misses.push_back(ObjectId(kNode + 1, ObjectType::Semaphore, index));
            misses.push_back(ObjectId(kNode, ObjectType::MessagePort, index));
        }
        misses.push_back(ObjectId::null());
        for (const ObjectId id : misses) {
            const auto resolved = table_.resolve(id);
            ObjectId owner = ObjectId(kNode, ObjectType::Task, 9);
            ASSERT_EQ(table_.find(id), resolved.ok() ? resolved.value() : nullptr) << std::hex << id.raw();
            ASSERT_EQ(table_.find(id, owner), resolved.ok() ? resolved.value() : nullptr) << std::hex << id.raw();
            if (!resolved.ok()) {
                ASSERT_EQ(owner, ObjectId(kNode, ObjectType::Task, 9)) << "a miss leaves the owner alone";
            }
        }
    }

    Table& table_;
    std::mt19937 random_;
    unsigned recoverPerMille_;
    std::map<uint32_t, ModelObject> objects_;
    std::deque<size_t> freeSlots_;
    std::vector<ObjectId> deleted_;
    size_t maxLive_ = 0;
};

} // namespace

TEST(ObjectTableTest, RandomOperationsAgreeWithAModelInASmallTable)
{
    // Eight slots share eight buckets: names collide in nearly every lookup.
    for (uint32_t seed = 1; seed <= 20; ++seed) {
        SCOPED_TRACE(seed);
        ObjectTable<Semaphore, 8> table(ObjectType::Semaphore, kNode);
        ObjectTableModelTest<ObjectTable<Semaphore, 8>> model(table, seed);
        model.run(2000);
        ASSERT_FALSE(::testing::Test::HasFailure());
    }
}

TEST(ObjectTableTest, RandomOperationsAgreeWithAModelWhenOwnersShareLists)
{
    for (uint32_t seed = 100; seed <= 110; ++seed) {
        SCOPED_TRACE(seed);
        ObjectTable<Semaphore, 64, FewOwnerKeys> table(ObjectType::Semaphore, kNode);
        ObjectTableModelTest<ObjectTable<Semaphore, 64, FewOwnerKeys>> model(table, seed);
        model.run(3000);
        ASSERT_FALSE(::testing::Test::HasFailure());
    }
}

TEST(ObjectTableTest, RandomOperationsAgreeWithAModelInAFullSizeTable)
{
    using Table = ObjectTable<Semaphore, 4096>;
    static Table table(ObjectType::Semaphore, kNode);
    ObjectTableModelTest<Table> model(table, 4096, 1);
    model.run(30000, 97);
    EXPECT_GT(model.maxLive(), 1000u);
}

namespace {

// An object of an odd size, so that its entries' stride is no power of two
// and its bookkeeping sits at another offset than a Semaphore's.
struct OddObject {
    char bytes[13] = {};
};

} // namespace

TEST(ObjectTableTest, TablesOfDifferentTypesShareACompiledCoreAndKeepTheirOwnState)
{
    // The configuration services run in ObjectTableCore, compiled once per
    // slot width and reaching the entries through a stride: two tables of
    // different object types and sizes but the same width, worked on in
    // turns, must each still agree with their own model.
    using SemaphoreTable = ObjectTable<Semaphore, 64, FewOwnerKeys>;
    using OddTable = ObjectTable<OddObject, 256>;
    for (uint32_t seed = 200; seed <= 205; ++seed) {
        SCOPED_TRACE(seed);
        const auto semaphores = std::make_unique<SemaphoreTable>(ObjectType::Semaphore, kNode);
        const auto odd = std::make_unique<OddTable>(ObjectType::Semaphore, kNode);
        ObjectTableModelTest<SemaphoreTable> semaphoreModel(*semaphores, seed);
        ObjectTableModelTest<OddTable> oddModel(*odd, seed + 1000, 20);
        for (int round = 0; round < 40; ++round) {
            semaphoreModel.run(50, 5);
            oddModel.run(50, 5);
            ASSERT_FALSE(::testing::Test::HasFailure());
        }
    }
}
