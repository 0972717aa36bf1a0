// The kernel's message-buffer area (seed 7.9): the buffers that hold queued
// port messages, shared by every port.
//
// The whole area is reserved at build time; AddMsgBufs activates more of it,
// and only active buffers are handed out. Free buffers form a singly linked
// list through their own link field, so taking and giving back cost O(1),
// and a whole chain (a port's level, when the port is deleted) goes back in
// O(1) as well. The class does no locking; the message port agent
// serialises access to it.
#pragma once

#include <dcos/MessagePortAgent.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// One buffer of the area: a message and the link that queues it.
struct MessageBuffer {
    MessageBuffer* next = nullptr;
    Message message{};
};

/// The free list over a caller-provided reserve of message buffers.
class MessageBufferPool {
public:
    /// Creates a pool over @p reserve, of which nothing is active yet.
    /// Constexpr, so that a static pool is constant initialised.
    constexpr MessageBufferPool(MessageBuffer* reserve, size_t capacity) : reserve_(reserve), capacity_(capacity) {}

    MessageBufferPool(const MessageBufferPool&) = delete;
    MessageBufferPool& operator=(const MessageBufferPool&) = delete;

    /// Configuration service: activates @p count more buffers of the reserve.
    ///
    /// Fails with InvalidArgument for 0, and with NoMemory when fewer than
    /// @p count are left in the reserve; a refused request activates
    /// nothing. Cost O(count).
    Status AddMsgBufs(size_t count);

    /// Takes a free buffer, or returns null when none is left. Cost O(1).
    /// Inline, as give(), for the fast paths of Send and Receive.
    MessageBuffer* take()
    {
        MessageBuffer* buffer = freeHead_;
        if (buffer != nullptr) {
            freeHead_ = buffer->next;
            buffer->next = nullptr;
            --free_;
        }
        return buffer;
    }

    /// Gives back one buffer taken from this pool. Cost O(1).
    void give(MessageBuffer& buffer)
    {
        buffer.next = freeHead_;
        freeHead_ = &buffer;
        ++free_;
    }

    /// Gives back a chain of @p count buffers linked from @p first to
    /// @p last through their next fields. Cost O(1).
    void giveChain(MessageBuffer& first, MessageBuffer& last, size_t count);

    /// Buffers free to take.
    size_t freeCount() const { return free_; }
    /// Buffers activated so far (free or holding a message).
    size_t activeCount() const { return active_; }
    /// Buffers reserved at build time.
    size_t capacity() const { return capacity_; }

private:
    MessageBuffer* reserve_;
    size_t capacity_;
    size_t active_ = 0;
    size_t free_ = 0;
    MessageBuffer* freeHead_ = nullptr;
};

} // namespace dcos::internal
