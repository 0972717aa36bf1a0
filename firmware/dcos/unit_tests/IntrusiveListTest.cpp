// Host tests for the intrusive doubly linked list.
#include <dcos/internal/IntrusiveList.hpp>

#include <gtest/gtest.h>

#include <vector>

using dcos::internal::IntrusiveList;
using dcos::internal::IntrusiveListNode;

namespace {

struct ReadyTag {};
struct OtherTag {};

struct Item : IntrusiveListNode<ReadyTag>, IntrusiveListNode<OtherTag> {
    explicit Item(int v) : value(v) {}
    int value;
};

template <typename List>
std::vector<int> values(List& list)
{
    std::vector<int> out;
    for (Item& item : list) {
        out.push_back(item.value);
    }
    return out;
}

} // namespace

TEST(IntrusiveListTest, PushBackAndPopFrontAreFifo)
{
    IntrusiveList<Item, ReadyTag> list;
    Item a(1), b(2), c(3);
    EXPECT_TRUE(list.isEmpty());
    EXPECT_EQ(list.popFront(), nullptr);
    list.pushBack(a);
    list.pushBack(b);
    list.pushBack(c);
    EXPECT_EQ(list.size(), 3u);
    EXPECT_EQ(&list.front(), &a);
    EXPECT_EQ(&list.back(), &c);
    EXPECT_EQ(list.popFront(), &a);
    EXPECT_FALSE(static_cast<IntrusiveListNode<ReadyTag>&>(a).isLinked());
    EXPECT_EQ(list.popFront(), &b);
    EXPECT_EQ(list.popFront(), &c);
    EXPECT_TRUE(list.isEmpty());
}

TEST(IntrusiveListTest, PushFrontInsertAfterAndInsertBefore)
{
    IntrusiveList<Item, ReadyTag> list;
    Item a(1), b(2), c(3), d(4), e(5);
    list.pushBack(b);
    list.pushFront(a);
    list.insertAfter(b, d);
    list.insertAfter(b, c);
    list.insertBefore(list.end(), e);
    EXPECT_EQ(values(list), (std::vector<int>{1, 2, 3, 4, 5}));
}

TEST(IntrusiveListTest, RemoveFromAnyPositionAndSelfUnlink)
{
    IntrusiveList<Item, ReadyTag> list;
    Item a(1), b(2), c(3);
    list.pushBack(a);
    list.pushBack(b);
    list.pushBack(c);
    list.remove(b);
    EXPECT_EQ(values(list), (std::vector<int>{1, 3}));
    static_cast<IntrusiveListNode<ReadyTag>&>(c).unlink();
    EXPECT_EQ(values(list), (std::vector<int>{1}));
    // Unlinking an unlinked node is harmless.
    static_cast<IntrusiveListNode<ReadyTag>&>(c).unlink();
    list.remove(a);
    EXPECT_TRUE(list.isEmpty());
}

TEST(IntrusiveListTest, ObjectCanSitOnTwoListsWithDifferentTags)
{
    IntrusiveList<Item, ReadyTag> ready;
    IntrusiveList<Item, OtherTag> other;
    Item a(1), b(2);
    ready.pushBack(a);
    ready.pushBack(b);
    other.pushBack(b);
    other.pushBack(a);
    EXPECT_EQ(values(ready), (std::vector<int>{1, 2}));
    EXPECT_EQ(values(other), (std::vector<int>{2, 1}));
    ready.remove(a);
    EXPECT_EQ(values(ready), (std::vector<int>{2}));
    EXPECT_EQ(values(other), (std::vector<int>{2, 1}));
}
