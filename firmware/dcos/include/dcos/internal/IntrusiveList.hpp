// Intrusive doubly linked list: the kernel's wait lists, time-wheel slots and
// reap list (the ready queues of seed 7.4.1 are rings, IntrusiveRing.hpp).
//
// The kernel never allocates when a task becomes ready or blocks: the links
// live inside the object itself. An object that must sit in several lists at
// once (a task in a wait list and in the time-out wheel) derives from one
// IntrusiveListNode per list, told apart by a tag type.
#pragma once

#include <stddef.h>

namespace dcos::internal {

template <typename T, typename Tag, typename Sentinel>
class IntrusiveList;

template <typename T, typename Key, typename Tag>
class SortedList;

template <typename T, typename Tag>
class IntrusiveRing;

/// The links an object embeds, by deriving from it, to be put in an IntrusiveList.
///
/// The list is circular around a sentinel, so a node can unlink itself in
/// O(1) without knowing which list it is on; an unlinked node has null links.
template <typename Tag = void>
class IntrusiveListNode {
public:
    constexpr IntrusiveListNode() = default;
    IntrusiveListNode(const IntrusiveListNode&) = delete;
    IntrusiveListNode& operator=(const IntrusiveListNode&) = delete;

    /// Whether the node is currently on a list.
    constexpr bool isLinked() const { return next_ != nullptr; }

    /// Removes the node from whatever list holds it; does nothing when unlinked. Cost O(1).
    void unlink()
    {
        if (next_ == nullptr) {
            return;
        }
        prev_->next_ = next_;
        next_->prev_ = prev_;
        prev_ = nullptr;
        next_ = nullptr;
    }

private:
    template <typename, typename, typename>
    friend class IntrusiveList;
    template <typename, typename, typename>
    friend class SortedList;
    template <typename, typename>
    friend class IntrusiveRing;
    friend struct TaskAssemblyLayout; // Checks the link offset the scheduler's assembly uses.

    // Links this unlinked node in front of @p position.
    void insertBefore(IntrusiveListNode* position)
    {
        next_ = position;
        prev_ = position->prev_;
        prev_->next_ = this;
        position->prev_ = this;
    }

    IntrusiveListNode* prev_ = nullptr;
    IntrusiveListNode* next_ = nullptr;
};

/// A doubly linked list of T, where T derives from IntrusiveListNode<Tag>.
///
/// Insertion and removal at either end and removal of any element cost O(1).
/// The list object must not move while it holds elements, because the
/// elements point at its sentinel; copying is therefore deleted. The
/// sentinel is a plain node unless a list needs it to carry more: a
/// SortedList gives it the smallest key, so its insertion walk stops there
/// without a test for the list's end.
template <typename T, typename Tag = void, typename Sentinel = IntrusiveListNode<Tag>>
class IntrusiveList {
public:
    /// The node type T must derive from.
    using Node = IntrusiveListNode<Tag>;

    /// Forward iterator over the elements, front to back.
    class Iterator {
    public:
        /// Creates an iterator positioned at @p node.
        constexpr explicit Iterator(Node* node) : node_(node) {}
        /// The element the iterator points at.
        T& operator*() const { return *static_cast<T*>(node_); }
        /// Member access on the element the iterator points at.
        T* operator->() const { return static_cast<T*>(node_); }
        /// Advances to the next element.
        Iterator& operator++()
        {
            node_ = node_->next_;
            return *this;
        }
        /// Iterators are equal when they point at the same node.
        friend bool operator==(const Iterator& a, const Iterator& b) { return a.node_ == b.node_; }

    private:
        friend class IntrusiveList;
        Node* node_;
    };

    /// Creates an empty list.
    IntrusiveList() { head_.prev_ = head_.next_ = &head_; }
    IntrusiveList(const IntrusiveList&) = delete;
    IntrusiveList& operator=(const IntrusiveList&) = delete;

    /// Whether the list holds no element. Cost O(1).
    bool isEmpty() const { return head_.next_ == &head_; }

    /// The first element; the list must not be empty. Cost O(1).
    T& front() const { return *static_cast<T*>(head_.next_); }
    /// The last element; the list must not be empty. Cost O(1).
    T& back() const { return *static_cast<T*>(head_.prev_); }

    /// Appends @p item, which must not be on any list of this Tag. Cost O(1).
    void pushBack(T& item) { node(item).insertBefore(&head_); }
    /// Prepends @p item, which must not be on any list of this Tag. Cost O(1).
    void pushFront(T& item) { node(item).insertBefore(head_.next_); }
    /// Inserts @p item in front of the element at @p position (end() appends). Cost O(1).
    void insertBefore(Iterator position, T& item) { node(item).insertBefore(position.node_); }

    /// Inserts @p item right behind @p position, which must be on this list. Cost O(1).
    void insertAfter(T& position, T& item) { node(item).insertBefore(node(position).next_); }

    /// Removes and returns the first element, or null when empty. Cost O(1).
    T* popFront()
    {
        if (isEmpty()) {
            return nullptr;
        }
        T* item = &front();
        node(*item).unlink();
        return item;
    }

    /// Removes @p item, which must be on this list. Cost O(1).
    void remove(T& item) { node(item).unlink(); }

    /// Number of elements. Cost O(N); kept off the hot paths on purpose, so
    /// that no counter has to be maintained when a node unlinks itself.
    size_t size() const
    {
        size_t count = 0;
        for (const Node* n = head_.next_; n != &head_; n = n->next_) {
            ++count;
        }
        return count;
    }

    /// Iterator to the first element.
    Iterator begin() { return Iterator(head_.next_); }
    /// Iterator past the last element.
    Iterator end() { return Iterator(&head_); }

private:
    template <typename, typename, typename>
    friend class SortedList;

    static Node& node(T& item) { return static_cast<Node&>(item); }

    Sentinel head_;
};

} // namespace dcos::internal
