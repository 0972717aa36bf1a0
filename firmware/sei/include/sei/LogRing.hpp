// The console's copy for the monitoring stream (docs/protocols/monitor.md,
// "Console output"): a fixed ring of bytes the console writes into and the
// system engineering interface agent's task reads out as Log frames. It
// never blocks and never allocates, so a console write from an interrupt
// handler or a panic costs a few instructions; when the ring is full the
// byte is counted, not waited for.
//
// Dropped bytes are reported exactly where they fell: once a byte is
// dropped the ring takes nothing more until the reader has emptied it, so
// every byte dropped lies after every byte the ring still holds and before
// every byte it takes afterwards. The reader sends what the ring holds,
// then takeLost() tells it how many bytes the Lost frame reports, and only
// then does the ring take bytes again.
//
// The ring itself is not synchronised: in the node every call runs with
// interrupts off (the console may write from any context), on the host in
// one thread. Pure code, the same in the node and the host tests.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace sei {

template <size_t Capacity>
class LogRing {
    static_assert(Capacity != 0 && (Capacity & (Capacity - 1)) == 0,
                  "a power of two, so the indices wrap with a mask and never overflow wrongly");

public:
    static constexpr size_t kCapacity = Capacity;

    /// Appends @p byte, or counts it dropped when the ring is full or is
    /// still reporting an earlier overflow; false when it was dropped.
    bool put(uint8_t byte)
    {
        if (overflowed_ || head_ - tail_ == Capacity) {
            overflowed_ = true;
            if (dropped_ != UINT32_MAX) {
                ++dropped_;
            }
            return false;
        }
        bytes_[head_ & (Capacity - 1)] = byte;
        ++head_;
        return true;
    }

    /// Copies up to @p max of the oldest bytes into @p out without taking
    /// them, so that a frame the bus could not take yet loses nothing; how
    /// many.
    size_t peek(uint8_t* out, size_t max) const
    {
        const uint32_t held = head_ - tail_;
        const size_t count = held < max ? held : max;
        for (size_t i = 0; i < count; ++i) {
            out[i] = bytes_[(tail_ + i) & (Capacity - 1)];
        }
        return count;
    }

    /// Takes the @p count oldest bytes (at most those held).
    void consume(size_t count)
    {
        const uint32_t held = head_ - tail_;
        tail_ += static_cast<uint32_t>(count < held ? count : held);
    }

    /// Once the ring is empty after an overflow: the bytes dropped, at most
    /// @p max of them (a Lost frame carries 16 bits), which are taken off the
    /// count; when the count reaches 0 the ring takes bytes again. 0 while
    /// bytes before the gap are still held, or when nothing was dropped.
    uint32_t takeLost(uint32_t max)
    {
        if (!overflowed_ || head_ != tail_) {
            return 0;
        }
        const uint32_t taken = dropped_ < max ? dropped_ : max;
        dropped_ -= taken;
        if (dropped_ == 0) {
            overflowed_ = false;
        }
        return taken;
    }

    /// Bytes held.
    size_t size() const { return head_ - tail_; }
    /// Whether there is anything for the reader: bytes or a gap to report.
    bool pending() const { return head_ != tail_ || overflowed_; }

    /// Forgets everything, the dropped count too: a new stream starts here.
    void clear()
    {
        tail_ = head_;
        dropped_ = 0;
        overflowed_ = false;
    }

private:
    uint8_t bytes_[Capacity] = {};
    uint32_t head_ = 0;
    uint32_t tail_ = 0;
    uint32_t dropped_ = 0;
    bool overflowed_ = false;
};

} // namespace sei
