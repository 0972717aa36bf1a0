// Host tests for the key-sorted intrusive list and the priority wait list built on it.
#include <dcos/internal/SortedList.hpp>
#include <dcos/internal/WaitList.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

using dcos::internal::SortedList;
using dcos::internal::SortedListNode;
using dcos::internal::WaitList;
using dcos::internal::WaitListNode;

namespace {

struct Waiter : WaitListNode<> {
    explicit Waiter(int v = 0) : id(v) {}
    int id;
};

std::vector<int> ids(WaitList<Waiter>& list)
{
    std::vector<int> out;
    for (Waiter& waiter : list) {
        out.push_back(waiter.id);
    }
    return out;
}

} // namespace

TEST(SortedListTest, WaitListOrdersByPriorityHighestFirst)
{
    WaitList<Waiter> list;
    Waiter low(1), high(2), middle(3);
    list.insert(low, 20);
    list.insert(high, 0);
    list.insert(middle, 7);
    EXPECT_EQ(ids(list), (std::vector<int>{2, 3, 1}));
    EXPECT_EQ(&list.front(), &high);
    EXPECT_EQ(WaitList<Waiter>::keyOf(middle), 7);
}

TEST(SortedListTest, EqualPrioritiesAreFirstComeFirstServed)
{
    WaitList<Waiter> list;
    Waiter a(1), b(2), c(3), d(4), e(5);
    list.insert(a, 5);
    list.insert(b, 5);
    list.insert(c, 3);
    list.insert(d, 5);
    list.insert(e, 3);
    EXPECT_EQ(ids(list), (std::vector<int>{3, 5, 1, 2, 4}));
    EXPECT_EQ(list.popFront(), &c);
    EXPECT_EQ(list.popFront(), &e);
    EXPECT_EQ(list.popFront(), &a);
}

TEST(SortedListTest, RepositionMovesBehindNewEquals)
{
    WaitList<Waiter> list;
    Waiter a(1), b(2), c(3);
    list.insert(a, 4);
    list.insert(b, 4);
    list.insert(c, 9);
    list.reposition(c, 4);
    EXPECT_EQ(ids(list), (std::vector<int>{1, 2, 3}));
    list.reposition(a, 4);
    EXPECT_EQ(ids(list), (std::vector<int>{2, 3, 1}));
    list.reposition(a, 0);
    EXPECT_EQ(ids(list), (std::vector<int>{1, 2, 3}));
    list.remove(b);
    EXPECT_EQ(ids(list), (std::vector<int>{1, 3}));
    EXPECT_EQ(list.size(), 2u);
}

TEST(SortedListTest, RandomInsertsMatchStableSort)
{
    std::mt19937 random(1234);
    Waiter waiters[200];
    std::vector<std::pair<uint8_t, int>> reference;
    WaitList<Waiter> list;
    for (int i = 0; i < 200; ++i) {
        waiters[i].id = i;
        const uint8_t priority = static_cast<uint8_t>(random() % 32);
        list.insert(waiters[i], priority);
        reference.emplace_back(priority, i);
    }
    std::stable_sort(reference.begin(), reference.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<int> expected;
    for (const auto& entry : reference) {
        expected.push_back(entry.second);
    }
    EXPECT_EQ(ids(list), expected);
}

TEST(SortedListTest, WideKeysSortAsUnsigned64)
{
    struct Timer : SortedListNode<uint64_t> {
        int id = 0;
    };
    SortedList<Timer, uint64_t> list;
    Timer a, b, c;
    a.id = 1;
    b.id = 2;
    c.id = 3;
    list.insert(a, UINT64_MAX);
    list.insert(b, uint64_t{1} << 40);
    list.insert(c, (uint64_t{1} << 40) + 1);
    EXPECT_EQ(list.popFront()->id, 2);
    EXPECT_EQ(list.popFront()->id, 3);
    EXPECT_EQ(list.popFront()->id, 1);
    EXPECT_TRUE(list.isEmpty());
}

// The insertion walk stops at the sentinel, whose key is zero: keys of zero,
// lists emptied and refilled, removals from the middle and pops must keep the
// order a stable sort of the live entries gives.
TEST(SortedListTest, RandomInsertRemovePopMatchesModelAcrossEmptyLists)
{
    std::mt19937 random(99);
    Waiter waiters[64];
    std::vector<std::pair<uint8_t, int>> model; // (key, id) in list order
    WaitList<Waiter> list;
    int sequence = 0;
    for (int step = 0; step < 20000; ++step) {
        const unsigned action = random() % 8;
        if (action < 4) {
            const int index = static_cast<int>(random() % 64);
            if (waiters[index].isLinked()) {
                continue;
            }
            // Small keys, zero among them, so that equal keys and the smallest key are frequent.
            const uint8_t key = static_cast<uint8_t>(random() % 4);
            waiters[index].id = index;
            list.insert(waiters[index], key);
            auto position = std::upper_bound(model.begin(), model.end(), key,
                                             [](uint8_t k, const auto& entry) { return k < entry.first; });
            model.insert(position, {key, index});
        } else if (action < 6) {
            Waiter* const front = list.popFront();
            if (model.empty()) {
                ASSERT_EQ(front, nullptr);
            } else {
                ASSERT_NE(front, nullptr);
                ASSERT_EQ(front->id, model.front().second);
                model.erase(model.begin());
            }
        } else {
            const int index = static_cast<int>(random() % 64);
            if (!waiters[index].isLinked()) {
                continue;
            }
            list.remove(waiters[index]);
            model.erase(std::find_if(model.begin(), model.end(),
                                     [index](const auto& entry) { return entry.second == index; }));
        }
        ++sequence;
        std::vector<int> expected;
        for (const auto& entry : model) {
            expected.push_back(entry.second);
        }
        ASSERT_EQ(ids(list), expected) << "after step " << step;
        ASSERT_EQ(list.isEmpty(), model.empty());
    }
    EXPECT_GT(sequence, 10000);
}
