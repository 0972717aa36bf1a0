// Host tests for the lists of held memory (HeldList.hpp): against a model
// under random take, give and transfer sequences, and with damaged links,
// out-of-service containers and wrong heads, which must mark a list lost
// and never write outside the links of items in service.
#include <dcos/internal/HeldList.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <deque>
#include <random>
#include <vector>

using dcos::internal::HeldHead;
using dcos::internal::HeldLinks;
using dcos::internal::HeldLinksCopy;
using dcos::internal::HeldList;
using dcos::internal::kHeldEnd;
using dcos::internal::kHeldFirst;
using dcos::internal::kHeldLost;
using dcos::internal::kHeldUnlisted;

namespace {

constexpr uint32_t kContainers = 4;
constexpr uint32_t kItems = 32;

// Four containers of 32 items each, the links of each in one array as a
// pool keeps them; a handle is the container in the high half and the item
// in the low one, as the buffer pool agent forms them.
struct Containers {
    std::array<std::array<uint8_t, kItems * HeldLinks::kBytes>, kContainers> links{};
    std::array<bool, kContainers> inService{true, true, true, true};

    static uint32_t handle(uint32_t container, uint32_t item) { return (container << 16) | item; }

    uint8_t* linksOf(uint32_t handle)
    {
        return links[handle >> 16].data() + (handle & 0xFFFF) * HeldLinks::kBytes;
    }

    auto resolver()
    {
        return [this](uint32_t handle) -> uint8_t* {
            const uint32_t container = handle >> 16;
            const uint32_t item = handle & 0xFFFF;
            if (container >= kContainers || item >= kItems || !inService[container]) {
                return nullptr;
            }
            return linksOf(handle);
        };
    }
};

std::vector<uint32_t> walk(Containers& containers, uint32_t head, bool& complete)
{
    std::vector<uint32_t> seen;
    complete = HeldList::forEach(head, containers.resolver(), [&seen](uint32_t handle, uint8_t*) {
        seen.push_back(handle);
        return seen.size() <= kContainers * kItems; // A bound, for a test that goes wrong.
    });
    return seen;
}

std::vector<uint32_t> walk(Containers& containers, uint32_t head)
{
    bool complete = false;
    std::vector<uint32_t> seen = walk(containers, head, complete);
    EXPECT_TRUE(complete);
    return seen;
}

} // namespace

TEST(HeldListTest, AnEmptyListHasNothing)
{
    Containers containers;
    EXPECT_TRUE(walk(containers, kHeldEnd).empty());
}

TEST(HeldListTest, ItemsComeOutNewestFirstAndLeaveFromAnywhere)
{
    Containers containers;
    uint32_t head = kHeldEnd;
    const uint32_t a = Containers::handle(0, 3);
    const uint32_t b = Containers::handle(2, 0);
    const uint32_t c = Containers::handle(1, 31);
    for (uint32_t item : {a, b, c}) {
        HeldList::pushFront(head, item, containers.linksOf(item), containers.resolver());
    }
    EXPECT_EQ(walk(containers, head), (std::vector<uint32_t>{c, b, a}));
    HeldList::remove(head, b, containers.linksOf(b), containers.resolver()); // The middle.
    EXPECT_EQ(walk(containers, head), (std::vector<uint32_t>{c, a}));
    HeldList::remove(head, c, containers.linksOf(c), containers.resolver()); // The first.
    EXPECT_EQ(walk(containers, head), (std::vector<uint32_t>{a}));
    HeldList::remove(head, a, containers.linksOf(a), containers.resolver()); // The last and only.
    EXPECT_EQ(head, kHeldEnd);
}

TEST(HeldListTest, AnUnlistedItemIsLeftAlone)
{
    Containers containers;
    uint32_t head = kHeldEnd;
    const uint32_t listed = Containers::handle(0, 1);
    const uint32_t system = Containers::handle(0, 2);
    HeldList::pushFront(head, listed, containers.linksOf(listed), containers.resolver());
    HeldList::setUnlisted(containers.linksOf(system));
    HeldList::remove(head, system, containers.linksOf(system), containers.resolver());
    EXPECT_EQ(walk(containers, head), (std::vector<uint32_t>{listed}));
}

TEST(HeldListTest, RemovingFromAnotherHoldersListMarksThatListLostAndSparesTheOther)
{
    Containers containers;
    uint32_t mine = kHeldEnd;
    uint32_t theirs = kHeldEnd;
    const uint32_t item = Containers::handle(1, 5);
    const uint32_t other = Containers::handle(1, 6);
    HeldList::pushFront(theirs, item, containers.linksOf(item), containers.resolver());
    HeldList::pushFront(mine, other, containers.linksOf(other), containers.resolver());
    HeldList::remove(mine, item, containers.linksOf(item), containers.resolver());
    EXPECT_EQ(mine, kHeldLost);
    EXPECT_EQ(walk(containers, theirs), (std::vector<uint32_t>{item}));
}

TEST(HeldListTest, ANeighbourInAContainerOutOfServiceMarksTheListLost)
{
    Containers containers;
    uint32_t head = kHeldEnd;
    const uint32_t first = Containers::handle(0, 0);
    const uint32_t gone = Containers::handle(3, 0);
    const uint32_t last = Containers::handle(0, 1);
    for (uint32_t item : {last, gone, first}) {
        HeldList::pushFront(head, item, containers.linksOf(item), containers.resolver());
    }
    containers.inService[3] = false; // Deleted or corrupted.
    bool complete = true;
    EXPECT_EQ(walk(containers, head, complete), (std::vector<uint32_t>{first}));
    EXPECT_FALSE(complete);
    const auto before = containers.links;
    HeldList::remove(head, first, containers.linksOf(first), containers.resolver());
    EXPECT_EQ(head, kHeldLost);
    EXPECT_EQ(containers.links, before) << "a failed check writes no link";
    // A lost list is no longer followed, and what is pushed onto it stays off it.
    const uint32_t later = Containers::handle(1, 0);
    HeldList::pushFront(head, later, containers.linksOf(later), containers.resolver());
    EXPECT_EQ(head, kHeldLost);
    EXPECT_EQ(HeldLinks::previous(containers.linksOf(later)), kHeldUnlisted);
    EXPECT_FALSE(walk(containers, head, complete).size());
    EXPECT_FALSE(complete);
}

TEST(HeldListTest, PushingOntoAListWhoseFirstNoLongerLinksBackMarksItLost)
{
    Containers containers;
    uint32_t head = kHeldEnd;
    const uint32_t first = Containers::handle(2, 7);
    HeldList::pushFront(head, first, containers.linksOf(first), containers.resolver());
    HeldLinks::setPrevious(containers.linksOf(first), Containers::handle(2, 8)); // A stray write.
    const uint32_t next = Containers::handle(2, 9);
    HeldList::pushFront(head, next, containers.linksOf(next), containers.resolver());
    EXPECT_EQ(head, kHeldLost);
    EXPECT_EQ(HeldLinks::previous(containers.linksOf(first)), Containers::handle(2, 8)) << "left as found";
}

TEST(HeldListTest, AForgedLoopEndsTheWalk)
{
    Containers containers;
    uint32_t head = kHeldEnd;
    const uint32_t a = Containers::handle(0, 0);
    const uint32_t b = Containers::handle(0, 1);
    HeldList::pushFront(head, b, containers.linksOf(b), containers.resolver());
    HeldList::pushFront(head, a, containers.linksOf(a), containers.resolver());
    HeldLinks::setNext(containers.linksOf(b), a); // b leads back to a, which says it is first.
    bool complete = true;
    EXPECT_EQ(walk(containers, head, complete), (std::vector<uint32_t>{a, b}));
    EXPECT_FALSE(complete);
}

TEST(HeldListTest, ADamagedNextLinkFailsTheRemovalOfItsSuccessor)
{
    Containers containers;
    uint32_t head = kHeldEnd;
    const uint32_t a = Containers::handle(1, 1);
    const uint32_t b = Containers::handle(1, 2);
    HeldList::pushFront(head, b, containers.linksOf(b), containers.resolver());
    HeldList::pushFront(head, a, containers.linksOf(a), containers.resolver());
    HeldLinks::setNext(containers.linksOf(a), Containers::handle(1, 3));
    const auto before = containers.links;
    HeldList::remove(head, b, containers.linksOf(b), containers.resolver());
    EXPECT_EQ(head, kHeldLost);
    EXPECT_EQ(containers.links, before);
}

TEST(HeldListTest, ACopyOfGoneLinksRemovesTheItem)
{
    Containers containers;
    uint32_t head = kHeldEnd;
    const uint32_t a = Containers::handle(0, 4);
    const uint32_t b = Containers::handle(0, 5);
    const uint32_t c = Containers::handle(0, 6);
    for (uint32_t item : {c, b, a}) {
        HeldList::pushFront(head, item, containers.linksOf(item), containers.resolver());
    }
    const uint32_t next = HeldLinks::next(containers.linksOf(b));
    const uint32_t previous = HeldLinks::previous(containers.linksOf(b));
    HeldLinks::setNext(containers.linksOf(b), 0x12345678); // Overwritten by a merge.
    HeldLinks::setPrevious(containers.linksOf(b), 0x9ABCDEF0);
    HeldLinksCopy copy(next, previous);
    HeldList::remove(head, b, copy.bytes, containers.resolver());
    EXPECT_EQ(walk(containers, head), (std::vector<uint32_t>{a, c}));
}

std::vector<uint32_t> walkHeld(Containers& containers, const HeldHead& head)
{
    std::vector<uint32_t> seen;
    EXPECT_TRUE(HeldList::forEachHeld(head, containers.resolver(), [&seen](uint32_t handle, uint8_t*) {
        seen.push_back(handle);
        return seen.size() <= kContainers * kItems;
    }));
    return seen;
}

TEST(HeldListTest, TakingAndGivingOneItemTouchesNoLink)
{
    Containers containers;
    HeldHead head{kHeldEnd, kHeldEnd};
    const uint32_t item = Containers::handle(1, 4);
    const auto before = containers.links;
    for (int round = 0; round < 3; ++round) {
        HeldList::take(head, item, containers.resolver());
        EXPECT_EQ(walkHeld(containers, head), (std::vector<uint32_t>{item}));
        HeldList::give(head, item, containers.linksOf(item), containers.resolver());
        EXPECT_TRUE(walkHeld(containers, head).empty());
    }
    EXPECT_EQ(containers.links, before);
    EXPECT_EQ(head.first, kHeldEnd);
}

TEST(HeldListTest, TheNewestIsLinkedWhenAnotherIsTaken)
{
    Containers containers;
    HeldHead head{kHeldEnd, kHeldEnd};
    const uint32_t a = Containers::handle(0, 1);
    const uint32_t b = Containers::handle(2, 2);
    const uint32_t c = Containers::handle(3, 3);
    HeldList::take(head, a, containers.resolver());
    HeldList::take(head, b, containers.resolver());
    EXPECT_EQ(head.newest, b);
    EXPECT_EQ(walk(containers, head.first), (std::vector<uint32_t>{a}));
    HeldList::take(head, c, containers.resolver());
    EXPECT_EQ(walkHeld(containers, head), (std::vector<uint32_t>{c, b, a}));
    HeldList::give(head, a, containers.linksOf(a), containers.resolver()); // Linked: off the list.
    EXPECT_EQ(walkHeld(containers, head), (std::vector<uint32_t>{c, b}));
}

TEST(HeldListTest, ANewestThatNoLongerResolvesLosesTheListWhenAnotherIsTaken)
{
    Containers containers;
    HeldHead head{kHeldEnd, kHeldEnd};
    HeldList::take(head, Containers::handle(3, 0), containers.resolver());
    containers.inService[3] = false;
    HeldList::take(head, Containers::handle(0, 0), containers.resolver());
    EXPECT_EQ(head.first, kHeldLost);
    EXPECT_FALSE(HeldList::forEachHeld(head, containers.resolver(), [](uint32_t, uint8_t*) { return true; }));
}

TEST(HeldListTest, RandomizedSequencesMatchTheModel)
{
    constexpr int kHolders = 3;
    std::mt19937 random(20261126);
    for (int round = 0; round < 40; ++round) {
        Containers containers;
        std::array<HeldHead, kHolders> heads;
        heads.fill(HeldHead{kHeldEnd, kHeldEnd});
        std::array<std::deque<uint32_t>, kHolders> model;
        std::vector<int> holderOf(kContainers * kItems, -1); // -1 free, kHolders the system.
        const auto handleOf = [](uint32_t flat) { return Containers::handle(flat / kItems, flat % kItems); };
        for (int step = 0; step < 400; ++step) {
            const uint32_t flat = static_cast<uint32_t>(random() % (kContainers * kItems));
            const uint32_t handle = handleOf(flat);
            uint8_t* const links = containers.linksOf(handle);
            const int holder = holderOf[flat];
            const int action = static_cast<int>(random() % 3);
            if (holder < 0) {
                const int taker = static_cast<int>(random() % (kHolders + 1));
                if (taker != kHolders) { // The system's items are on no list.
                    HeldList::take(heads[taker], handle, containers.resolver());
                    model[taker].push_front(handle);
                }
                holderOf[flat] = taker;
            } else if (action == 0 || holder == kHolders) {
                if (holder != kHolders) {
                    HeldList::give(heads[holder], handle, links, containers.resolver());
                    model[holder].erase(std::find(model[holder].begin(), model[holder].end(), handle));
                }
                holderOf[flat] = -1;
            } else {
                const int to = static_cast<int>(random() % kHolders);
                HeldList::give(heads[holder], handle, links, containers.resolver());
                model[holder].erase(std::find(model[holder].begin(), model[holder].end(), handle));
                HeldList::take(heads[to], handle, containers.resolver());
                model[to].push_front(handle);
                holderOf[flat] = to;
            }
            for (int h = 0; h < kHolders; ++h) {
                ASSERT_NE(heads[h].first, kHeldLost) << "round " << round << " step " << step;
                ASSERT_EQ(walkHeld(containers, heads[h]), std::vector<uint32_t>(model[h].begin(), model[h].end()))
                    << "round " << round << " step " << step << " holder " << h;
            }
        }
    }
}
