// Host tests for the head-only ring the ready queues use.
#include <dcos/internal/IntrusiveList.hpp>
#include <dcos/internal/IntrusiveRing.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <random>
#include <vector>

using dcos::internal::IntrusiveList;
using dcos::internal::IntrusiveListNode;
using dcos::internal::IntrusiveRing;

namespace {

struct Item : IntrusiveListNode<> {
    int id = 0;
};

std::vector<int> ids(const IntrusiveRing<Item>& ring)
{
    std::vector<int> out;
    if (ring.isEmpty()) {
        return out;
    }
    Item* item = &ring.front();
    do {
        out.push_back(item->id);
        item = &IntrusiveRing<Item>::next(*item);
    } while (item != &ring.front());
    return out;
}

} // namespace

TEST(IntrusiveRingTest, EmptyRingHasNoFront)
{
    IntrusiveRing<Item> ring;
    EXPECT_TRUE(ring.isEmpty());
    EXPECT_EQ(ring.size(), 0u);
}

TEST(IntrusiveRingTest, RotateMovesTheFrontBehindItsEquals)
{
    IntrusiveRing<Item> ring;
    Item a, b, c;
    a.id = 1;
    b.id = 2;
    c.id = 3;
    ring.pushBack(a);
    EXPECT_EQ(ring.rotate(), nullptr) << "one element: nothing to rotate";
    EXPECT_TRUE(ring.isFront(a));
    ring.pushBack(b);
    ring.pushBack(c);
    EXPECT_EQ(ids(ring), (std::vector<int>{1, 2, 3}));
    EXPECT_EQ(ring.rotate(), &b);
    EXPECT_EQ(ids(ring), (std::vector<int>{2, 3, 1}));
    EXPECT_EQ(&ring.back(), &a);
}

TEST(IntrusiveRingTest, RemovingTheLastElementEmptiesTheRingAndUnlinksIt)
{
    IntrusiveRing<Item> ring;
    Item a, b;
    ring.pushBack(a);
    ring.pushBack(b);
    EXPECT_FALSE(ring.remove(a));
    EXPECT_FALSE(a.isLinked());
    EXPECT_TRUE(ring.isFront(b));
    EXPECT_TRUE(ring.remove(b));
    EXPECT_FALSE(b.isLinked());
    EXPECT_TRUE(ring.isEmpty());
}

TEST(IntrusiveRingTest, NodeMovesBetweenARingAndAListOfTheSameTag)
{
    IntrusiveRing<Item> ring;
    IntrusiveList<Item> list;
    Item a, b;
    ring.pushBack(a);
    ring.pushBack(b);
    (void)ring.remove(a);
    list.pushBack(a);
    EXPECT_EQ(&list.front(), &a);
    a.unlink();
    EXPECT_TRUE(list.isEmpty());
    ring.pushBack(a);
    EXPECT_EQ(ring.size(), 2u);
}

// A randomized model: a deque is the queue in order, front first.
TEST(IntrusiveRingTest, RandomOperationsMatchADequeModel)
{
    std::mt19937 random(4242);
    Item items[16];
    for (int i = 0; i < 16; ++i) {
        items[i].id = i;
    }
    IntrusiveRing<Item> ring;
    std::deque<int> model;
    for (int step = 0; step < 50000; ++step) {
        const unsigned action = random() % 4;
        const int index = static_cast<int>(random() % 16);
        if (action == 0 && !items[index].isLinked()) {
            ring.pushBack(items[index]);
            model.push_back(index);
        } else if (action == 1 && items[index].isLinked()) {
            const bool emptied = ring.remove(items[index]);
            model.erase(std::find(model.begin(), model.end(), index));
            ASSERT_EQ(emptied, model.empty());
            ASSERT_FALSE(items[index].isLinked());
        } else if (action == 2 && !model.empty()) {
            Item* const next = ring.rotate();
            if (model.size() == 1) {
                ASSERT_EQ(next, nullptr);
            } else {
                model.push_back(model.front());
                model.pop_front();
                ASSERT_EQ(next, &items[model.front()]);
            }
        }
        ASSERT_EQ(ids(ring), std::vector<int>(model.begin(), model.end())) << "after step " << step;
        ASSERT_EQ(ring.size(), model.size());
        if (!model.empty()) {
            ASSERT_TRUE(ring.isFront(items[model.front()]));
            ASSERT_EQ(&ring.back(), &items[model.back()]);
        }
    }
}
