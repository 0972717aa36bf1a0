// A fixed-capacity single-producer, single-consumer ring buffer.
//
// The console driver's interrupt handler is the producer of received bytes
// and the shell the consumer, and the reverse for transmission. With one
// producer and one consumer on a uniprocessor node, each index is written by
// only one side, so no lock is needed: the producer publishes a byte by
// advancing head after storing it, and the consumer frees a slot by
// advancing tail after reading it. Capacity is a power of two so that the
// free-running indices wrap with a mask instead of a division.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace runtime {

template <typename Element, size_t Capacity>
class RingBuffer {
    static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0,
                  "RingBuffer capacity must be a power of two");
    static_assert(Capacity <= 0x8000, "RingBuffer indices are 16 bits wide");

public:
    /// Stores one element; returns false, storing nothing, when full.
    bool push(const Element& element)
    {
        const uint16_t head = head_;
        if (static_cast<uint16_t>(head - tail_) == Capacity) {
            return false;
        }
        storage_[head & mask] = element;
        asm volatile("" ::: "memory"); // Store the element before publishing it.
        head_ = static_cast<uint16_t>(head + 1);
        return true;
    }

    /// Removes the oldest element into element; returns false when empty.
    bool pop(Element& element)
    {
        const uint16_t tail = tail_;
        if (tail == head_) {
            return false;
        }
        element = storage_[tail & mask];
        asm volatile("" ::: "memory"); // Read the element before freeing its slot.
        tail_ = static_cast<uint16_t>(tail + 1);
        return true;
    }

    /// Number of elements stored.
    size_t size() const { return static_cast<uint16_t>(head_ - tail_); }
    bool empty() const { return head_ == tail_; }
    bool full() const { return size() == Capacity; }
    static constexpr size_t capacity() { return Capacity; }

private:
    static constexpr uint16_t mask = static_cast<uint16_t>(Capacity - 1);
    Element storage_[Capacity]{};
    volatile uint16_t head_ = 0;
    volatile uint16_t tail_ = 0;
};

} // namespace runtime
