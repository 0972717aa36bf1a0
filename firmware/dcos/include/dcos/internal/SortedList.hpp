// Intrusive list kept sorted by a key stored in each node.
//
// Two kernel queues need "sorted, first come first served among equals":
// the priority wait lists of blocking primitives (key: static priority) and
// the slots of the timer agent's time wheel (key: due tick). Both use this
// one template, so neither allocates when a task blocks or a timer is set.
#pragma once

#include <dcos/internal/IntrusiveList.hpp>

#include <stddef.h>
#include <type_traits>

namespace dcos::internal {

template <typename T, typename Key, typename Tag>
class SortedList;

/// The links and sort key an object embeds, by deriving from it, to be put in a SortedList.
template <typename Key, typename Tag = void>
class SortedListNode : public IntrusiveListNode<Tag> {
public:
    /// The key the node was inserted with; meaningful only while linked.
    constexpr Key sortKey() const { return key_; }

private:
    template <typename, typename, typename>
    friend class SortedList;

    Key key_{};
};

/// A list of T ordered by ascending key, FIFO among equal keys.
///
/// T derives from SortedListNode<Key, Tag>. Insertion walks from the back,
/// so inserting behind all equal or smaller keys (the common case of a new
/// waiter at a priority already waiting, or a timer later than all others)
/// costs O(1), and the worst case is O(N) in the list length. Removal of any
/// element and popping the front cost O(1).
template <typename T, typename Key, typename Tag = void>
class SortedList {
public:
    /// The node type T must derive from.
    using Node = SortedListNode<Key, Tag>;
    /// Iterator over the elements in ascending key order.
    using Iterator = typename IntrusiveList<T, Tag, Node>::Iterator;

    /// Creates an empty list.
    SortedList() = default;
    SortedList(const SortedList&) = delete;
    SortedList& operator=(const SortedList&) = delete;

    /// Whether the list holds no element. Cost O(1).
    bool isEmpty() const { return list_.isEmpty(); }
    /// The element with the smallest key; the list must not be empty. Cost O(1).
    T& front() const { return list_.front(); }
    /// The key of @p item as stored at insertion. Cost O(1).
    static Key keyOf(const T& item) { return static_cast<const Node&>(item).key_; }

    /// Inserts @p item, which must be unlinked, behind every element whose key is <= @p key.
    ///
    /// Cost O(number of elements with a larger key).
    void insert(T& item, Key key)
    {
        Node& inserted = item;
        inserted.key_ = key;
        // The walk starts at the last element, or at the sentinel of an
        // empty list, and stops at the first key not above @p key. The
        // sentinel holds the smallest key, so the walk needs no test for
        // the list's front, and inserting into an empty list costs what
        // inserting behind a smaller last key does.
        IntrusiveListNode<Tag>* position = list_.head_.prev_;
        while (key < static_cast<Node*>(position)->key_) {
            position = position->prev_;
        }
        inserted.insertBefore(position->next_);
    }

    /// Removes @p item, which must be on this list. Cost O(1).
    void remove(T& item) { list_.remove(item); }

    /// Moves @p item, which must be on this list, to the place of @p key.
    ///
    /// Used when a waiting task's priority changes (ChangePriority, priority
    /// inheritance); it goes behind its new equals as if it had just arrived.
    /// Cost as for insert.
    void reposition(T& item, Key key)
    {
        list_.remove(item);
        insert(item, key);
    }

    /// Removes and returns the element with the smallest key, or null when empty. Cost O(1).
    T* popFront() { return list_.popFront(); }

    /// Number of elements. Cost O(N).
    size_t size() const { return list_.size(); }

    /// Iterator to the element with the smallest key.
    Iterator begin() { return list_.begin(); }
    /// Iterator past the element with the largest key.
    Iterator end() { return list_.end(); }

private:
    static_assert(std::is_unsigned_v<Key>, "the sentinel's key, zero, must be the smallest key");

    IntrusiveList<T, Tag, Node> list_;
};

} // namespace dcos::internal
