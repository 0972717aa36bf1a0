// Ready queue of the dynamic (deadline) scheduler (dissertation 7.4.1, Fig. 7.7).
#pragma once

#include <dcos/Status.hpp>
#include <dcos/internal/DeadlineKey.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

template <typename T, size_t Capacity>
class DeadlineQueue;

/// The scheduling state a task embeds, by deriving from it, to be put in a DeadlineQueue.
///
/// The node remembers its position in the heap so that a task can leave the
/// queue (block, ClearDeadline, KillTask) in O(log N) without a search.
class DeadlineQueueNode {
public:
    constexpr DeadlineQueueNode() = default;
    DeadlineQueueNode(const DeadlineQueueNode&) = delete;
    DeadlineQueueNode& operator=(const DeadlineQueueNode&) = delete;

    /// Whether the node is currently in a queue.
    constexpr bool isQueued() const { return heapIndex_ != kNotQueued; }
    /// The key the node was inserted with; meaningful only while queued.
    constexpr const DeadlineKey& deadlineKey() const { return key_; }

private:
    template <typename, size_t>
    friend class DeadlineQueue;

    static constexpr uint16_t kNotQueued = 0xFFFF;

    DeadlineKey key_{};
    uint64_t arrivalOrder_ = 0;
    uint16_t heapIndex_ = kNotQueued;
};

/// Four-ary min-heap of deadline tasks over a static array of node pointers.
///
/// Four children per node rather than two halve the heap's height, so a
/// task made ready (sift-up: one comparison per level) climbs half as many
/// levels: three for the seed's 64 deadline tasks instead of six. Taking a
/// task out (sift-down) compares up to four children per level over half
/// the levels, as many comparisons as in a binary heap. Readying is the
/// path whose latency the deadline scheduler's figure measures.
///
/// The heap needs a strict order, which the seed obtains from its tie-break
/// rules; the last rule, first come first served, is an insertion sequence
/// number kept here, so no two nodes ever compare equal. T derives from
/// DeadlineQueueNode. Nothing is allocated: the heap is an array of
/// Capacity pointers to the tasks' own nodes.
template <typename T, size_t Capacity>
class DeadlineQueue {
    static_assert(Capacity > 0 && Capacity < DeadlineQueueNode::kNotQueued, "heap index is 16 bits");

public:
    /// Creates an empty queue.
    constexpr DeadlineQueue() = default;
    DeadlineQueue(const DeadlineQueue&) = delete;
    DeadlineQueue& operator=(const DeadlineQueue&) = delete;

    /// Maximum number of queued tasks.
    static constexpr size_t capacity() { return Capacity; }
    /// Number of queued tasks. Cost O(1).
    constexpr size_t size() const { return size_; }
    /// Whether no deadline task is ready. Cost O(1).
    constexpr bool isEmpty() const { return size_ == 0; }

    /// Queues @p item with @p key, behind every task it fully ties with.
    ///
    /// Fails with InvalidArgument when @p item is already queued and with
    /// TableFull when Capacity tasks are queued. Cost O(log N).
    Status insert(T& item, const DeadlineKey& key)
    {
        Node& node = item;
        if (node.isQueued()) {
            return Status::InvalidArgument;
        }
        if (size_ == Capacity) {
            return Status::TableFull;
        }
        node.key_ = key;
        node.arrivalOrder_ = nextArrival_++;
        place(&node, size_);
        ++size_;
        siftUp(node.heapIndex_);
        return Status::Ok;
    }

    /// Removes @p item from anywhere in the queue.
    ///
    /// Fails with NotFound when @p item is not queued. Cost O(log N).
    Status remove(T& item)
    {
        Node& node = item;
        if (!node.isQueued() || node.heapIndex_ >= size_ || heap_[node.heapIndex_] != &node) {
            return Status::NotFound;
        }
        const size_t index = node.heapIndex_;
        node.heapIndex_ = Node::kNotQueued;
        --size_;
        if (index != size_) {
            // The last element fills the hole and may need to move either way.
            Node* moved = heap_[size_];
            place(moved, index);
            siftUp(index);
            siftDown(moved->heapIndex_);
        }
        heap_[size_] = nullptr;
        return Status::Ok;
    }

    /// The task that must run first, or null when empty. Cost O(1).
    T* peek() const { return size_ == 0 ? nullptr : static_cast<T*>(heap_[0]); }

    /// Removes and returns the task that must run first, or null when empty. Cost O(log N).
    T* pop()
    {
        T* first = peek();
        if (first != nullptr) {
            (void)remove(*first); // Cannot fail: the head is queued.
        }
        return first;
    }

private:
    using Node = DeadlineQueueNode;

    /// Children per node.
    static constexpr size_t kArity = 4;

    static bool before(const Node* a, const Node* b)
    {
        // Keys almost always differ in their packed priority and latest
        // start: one 64-bit comparison decides, the tie-breaks are rare.
        if (a->key_.encoded() != b->key_.encoded()) {
            return a->key_.encoded() < b->key_.encoded();
        }
        if (a->key_.precedes(b->key_)) {
            return true;
        }
        if (b->key_.precedes(a->key_)) {
            return false;
        }
        return a->arrivalOrder_ < b->arrivalOrder_;
    }

    void place(Node* node, size_t index)
    {
        heap_[index] = node;
        node->heapIndex_ = static_cast<uint16_t>(index);
    }

    void siftUp(size_t index)
    {
        Node* node = heap_[index];
        while (index > 0) {
            const size_t parent = (index - 1) / kArity;
            if (!before(node, heap_[parent])) {
                break;
            }
            place(heap_[parent], index);
            index = parent;
        }
        place(node, index);
    }

    void siftDown(size_t index)
    {
        Node* node = heap_[index];
        for (;;) {
            const size_t first = kArity * index + 1;
            if (first >= size_) {
                break;
            }
            const size_t end = first + kArity < size_ ? first + kArity : size_;
            size_t child = first;
            for (size_t other = first + 1; other < end; ++other) {
                if (before(heap_[other], heap_[child])) {
                    child = other;
                }
            }
            if (!before(heap_[child], node)) {
                break;
            }
            place(heap_[child], index);
            index = child;
        }
        place(node, index);
    }

    Node* heap_[Capacity] = {};
    size_t size_ = 0;
    // 64 bits so the first-come order cannot wrap within the life of the system.
    uint64_t nextArrival_ = 0;
};

} // namespace dcos::internal
