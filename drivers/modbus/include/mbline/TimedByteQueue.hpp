// Received bytes with the time each arrived, from the UART's interrupt to
// the line's task.
//
// Modbus RTU frames are delimited by silences (t1.5 inside a frame, t3.5
// between frames, [SL] 2.5.1.1), so the receive state machine needs each
// character's arrival time, not only the character. The interrupt handler
// stamps every byte as it takes it from the 16550 (trigger level 1, so the
// FIFO does not hold bytes back until its 4-character time-out, which is
// longer than t3.5) and pushes it here; the task pops the pairs in order.
// One producer (the interrupt) and one consumer (the task), no lock: the
// indices are written by one side each. A full queue drops the newest byte
// and counts it; the frame it belonged to then fails its CRC or length and
// is discarded by the receiver, which is what RTU does with a lost byte.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace mbline {

struct TimedByte {
    uint8_t byte = 0;
    bool damaged = false; ///< The UART flagged it: parity or framing error, or a break.
    uint64_t timeNs = 0;  ///< When the UART delivered it (uptime, ns).
};

template <size_t Capacity>
class TimedByteQueue {
public:
    static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "the capacity is a power of two");

    /// From the interrupt: false (and counted) when the queue is full.
    bool push(uint8_t byte, uint64_t timeNs, bool damaged = false)
    {
        const uint32_t head = head_;
        if (head - tail_ == Capacity) {
            overflows_ = overflows_ + 1;
            return false;
        }
        slots_[head & (Capacity - 1)] = TimedByte{byte, damaged, timeNs};
        // The slot is written before the index that publishes it.
        __atomic_store_n(&head_, head + 1, __ATOMIC_RELEASE);
        return true;
    }

    /// From the task: the oldest byte, false when none waits.
    bool pop(TimedByte& out)
    {
        const uint32_t tail = tail_;
        if (__atomic_load_n(&head_, __ATOMIC_ACQUIRE) == tail) {
            return false;
        }
        out = slots_[tail & (Capacity - 1)];
        __atomic_store_n(&tail_, tail + 1, __ATOMIC_RELEASE);
        return true;
    }

    /// Empties the queue; only while the producer is stopped.
    void clear() { tail_ = head_; }

    bool empty() const { return __atomic_load_n(&head_, __ATOMIC_ACQUIRE) == tail_; }
    uint32_t overflows() const { return overflows_; }
    static constexpr size_t capacity() { return Capacity; }

private:
    TimedByte slots_[Capacity] = {};
    volatile uint32_t head_ = 0;
    volatile uint32_t tail_ = 0;
    volatile uint32_t overflows_ = 0;
};

} // namespace mbline
