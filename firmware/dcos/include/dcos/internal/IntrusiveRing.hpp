// Intrusive circular list without a sentinel: the ready queues of seed 7.4.1.
//
// A ready queue is round-robin: Yield and the end of a time slice move the
// running task, its head, behind its equals. In an IntrusiveList that takes
// two unlinks and two links around the sentinel; in a ring whose only handle
// is a pointer to its head, it is one store, head = head->next, because the
// old head is then the last element. The price is that a node cannot leave
// without its ring (the head may have to move), which the scheduler can
// afford: it always knows a ready task's queue from its priority.
#pragma once

#include <dcos/internal/IntrusiveList.hpp>

namespace dcos::internal {

/// A circular doubly linked list of T, where T derives from
/// IntrusiveListNode<Tag>, known by its head alone.
///
/// The nodes are IntrusiveListNodes, so an object may sit in a ring and, at
/// other times, in an IntrusiveList of the same Tag; an unlinked node has
/// null links in both. Every operation costs O(1) except size().
template <typename T, typename Tag = void>
class IntrusiveRing {
public:
    /// The node type T must derive from.
    using Node = IntrusiveListNode<Tag>;

    constexpr IntrusiveRing() = default;
    IntrusiveRing(const IntrusiveRing&) = delete;
    IntrusiveRing& operator=(const IntrusiveRing&) = delete;

    /// Whether the ring holds no element.
    bool isEmpty() const { return head_ == nullptr; }
    /// Whether @p item is the first element.
    bool isFront(const T& item) const { return head_ == static_cast<const Node*>(&item); }
    /// The first element; the ring must not be empty.
    T& front() const { return *static_cast<T*>(head_); }
    /// The last element; the ring must not be empty.
    T& back() const { return *static_cast<T*>(head_->prev_); }

    /// Appends @p item, which must not be on any list or ring of this Tag.
    void pushBack(T& item)
    {
        Node& node = item;
        if (head_ == nullptr) {
            node.prev_ = node.next_ = &node;
            head_ = &node;
        } else {
            node.insertBefore(head_);
        }
    }

    /// Removes @p item, which must be on this ring; returns true when the ring is now empty.
    bool remove(T& item)
    {
        Node& node = item;
        if (node.next_ == &node) {
            node.prev_ = node.next_ = nullptr;
            head_ = nullptr;
            return true;
        }
        if (head_ == &node) {
            head_ = node.next_;
        }
        node.unlink();
        return false;
    }

    /// Makes the second element the first, and so the first the last, and
    /// returns the new first one; with one element, changes nothing and
    /// returns null. The ring must not be empty. The round-robin step.
    T* rotate()
    {
        Node* const second = head_->next_;
        if (second == head_) {
            return nullptr;
        }
        head_ = second;
        return static_cast<T*>(second);
    }

    /// Number of elements. Cost O(N), for tests and diagnostics.
    size_t size() const
    {
        if (head_ == nullptr) {
            return 0;
        }
        size_t count = 1;
        for (const Node* node = head_->next_; node != head_; node = node->next_) {
            ++count;
        }
        return count;
    }

    /// The element after @p item, which must be on this ring, wrapping from the last to the first.
    static T& next(T& item) { return *static_cast<T*>(static_cast<Node&>(item).next_); }

private:
    Node* head_ = nullptr;
};

} // namespace dcos::internal
