// The queue of one message port (seed 7.9): FIFO, priority and LIFO order
// in constant time.
//
// A port keeps one singly linked list per priority level, 32 in all, and a
// bitmap with a bit set for every level holding messages, like the
// scheduler's ready bitmap (Fig. 7.5). Queuing at the tail (first in first
// out) or the head (last in first out) of a level is O(1) through the
// level's head and tail pointers, and the first message of the most urgent
// level is found with one bit scan, so Send and Receive cost the same
// however many messages wait. A FIFO port uses level 0 only.
//
// The class is portable, so the ordering is tested on the host; the
// message port agent adds the locking and the waiting receiver.
#pragma once

#include <dcos/MessagePortAgent.hpp>
#include <dcos/internal/MessageBufferPool.hpp>
#include <dcos/internal/ReadyBitmap.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// The messages queued on one port, in the order Receive takes them.
class MessageQueue {
public:
    /// Number of priority levels.
    static constexpr uint8_t kLevels = ReadyBitmap::kLevels;

    /// Where a message of a given priority goes.
    struct Placement {
        uint8_t level; ///< 0 (most urgent) to 31.
        bool lifo;     ///< At the head of its level rather than the tail.
    };

    /// Whether @p priority is one Send accepts: kLifoMostUrgent (-32) to 31.
    static constexpr bool isValidPriority(int priority)
    {
        return priority >= kLifoMostUrgent && priority <= kLeastUrgentMessage;
    }

    /// Maps a valid Send priority to its level and end on a port of @p order.
    ///
    /// 0 to 31: the tail of that level. -1 to -31: the head of level 1 to
    /// 31; kLifoMostUrgent: the head of level 0, since -0 is 0. A FIFO port
    /// puts everything on level 0 and honours only the sign. Cost O(1).
    static constexpr Placement placementOf(PortOrder order, int priority)
    {
        const bool lifo = priority < 0;
        const unsigned magnitude = lifo ? static_cast<unsigned>(-priority) % kLevels : static_cast<unsigned>(priority);
        return Placement{order == PortOrder::Fifo ? uint8_t{0} : static_cast<uint8_t>(magnitude), lifo};
    }

    /// Creates an empty queue of @p order.
    explicit constexpr MessageQueue(PortOrder order = PortOrder::Priority) : order_(order), levelMask_(maskOf(order)) {}

    MessageQueue(const MessageQueue&) = delete;
    MessageQueue& operator=(const MessageQueue&) = delete;

    /// The order this queue keeps.
    PortOrder order() const { return order_; }

    /// Changes the order; only an empty queue may change it (a new port).
    void reset(PortOrder order)
    {
        order_ = order;
        levelMask_ = maskOf(order);
    }

    /// Queues @p buffer for a Send of @p priority, which must be valid. Cost
    /// O(1). Inline, as takeFirst(), because Send and Receive are its fast paths.
    void post(MessageBuffer& buffer, int priority)
    {
        // placementOf(order_, priority), with the order as a mask: the
        // magnitude is at most 32, and its low five bits are the level.
        const bool lifo = priority < 0;
        const uint8_t levelNumber =
            static_cast<uint8_t>((lifo ? static_cast<unsigned>(-priority) : static_cast<unsigned>(priority)) & levelMask_);
        Level& level = level_[levelNumber];
        if (level.head == nullptr) {
            buffer.next = nullptr;
            level.head = level.tail = &buffer;
            levels_.set(levelNumber);
        } else if (lifo) {
            buffer.next = level.head;
            level.head = &buffer;
        } else {
            buffer.next = nullptr;
            level.tail->next = &buffer;
            level.tail = &buffer;
        }
        ++count_;
    }

    /// Takes the message Receive gets next, or null when empty. Cost O(1).
    MessageBuffer* takeFirst()
    {
        const uint8_t first = levels_.highest();
        if (first == ReadyBitmap::kNone) {
            return nullptr;
        }
        Level& level = level_[first];
        MessageBuffer* buffer = level.head;
        level.head = buffer->next;
        if (level.head == nullptr) {
            level.tail = nullptr;
            levels_.clearHighest(); // first is the highest level.
        }
        --count_;
        return buffer;
    }

    /// Hands every queued buffer back to @p pool and leaves the queue
    /// empty. Cost O(levels): each level goes back as one chain.
    void clear(MessageBufferPool& pool);

    /// Whether no message is queued. Cost O(1).
    bool isEmpty() const { return levels_.isEmpty(); }
    /// Number of messages queued. Cost O(1).
    size_t count() const { return count_; }
    /// Bit n set while level n holds messages, for diagnostics.
    uint32_t levelBits() const { return levels_.bits(); }

private:
    struct Level {
        MessageBuffer* head = nullptr;
        MessageBuffer* tail = nullptr;
    };

    static constexpr uint8_t maskOf(PortOrder order) { return order == PortOrder::Fifo ? 0 : kLevels - 1; }

    Level level_[kLevels] = {};
    ReadyBitmap levels_;
    size_t count_ = 0;
    PortOrder order_;
    uint8_t levelMask_; // kLevels - 1, or 0 for a FIFO port: every message on level 0.
};

} // namespace dcos::internal
