// One direction of the dual-Pentium board's shared-memory network (seed 9.2:
// nodes 2 and 3 talk through shared memory and inter-processor interrupts):
// a ring of fixed-size message slots in memory both processors see, with one
// writer and one reader, on different processors.
//
// No lock: each index has one writer. The writer fills a slot, then
// publishes it by advancing head; the reader takes it, then frees it by
// advancing tail. x86 processors keep stores in program order as other
// processors see them and do not move loads ahead of older loads (Intel SDM
// Vol. 3A, 9.2.2), so with the compiler held to program order too (volatile
// indices and a compiler barrier) a reader that sees the new head sees the
// slot's bytes, and a writer that sees the new tail may reuse the slot.
//
// The indices count up and wrap at 2^32; the slot is index % kSlots, and
// head - tail, modulo 2^32, is how many slots are full. A reader refuses
// indices that say more than kSlots are full (memory overwritten by a fault
// elsewhere) instead of reading garbage as messages.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace bsp {

/// One message in a slot: a system message of the network interfaces
/// manager (dcos/NetworkLink.hpp), its fields at fixed offsets.
struct SharedMemoryMessage {
    uint8_t priority;
    uint8_t type;
    uint8_t length;
    uint8_t reserved;
    uint32_t destination;
    uint32_t source;
    uint8_t data[8];
};
static_assert(sizeof(SharedMemoryMessage) == 20);

class SharedMemoryRing {
public:
    /// Slots per ring: a power of two, so that the index wraps cleanly.
    static constexpr uint32_t kSlots = 64;
    static_assert((kSlots & (kSlots - 1)) == 0);

    /// Empties the ring. Only while neither side uses it (the board's node 2
    /// does it before node 3 starts).
    void reset();

    /// Writes @p message into the next slot and publishes it; false (nothing
    /// written) when every slot is full. Writer only.
    bool push(const SharedMemoryMessage& message);

    /// Takes the oldest message into @p message; Empty when there is none,
    /// Corrupted when the indices say more slots are full than the ring has
    /// (nothing is taken). Reader only.
    enum class Pop : uint8_t { Taken, Empty, Corrupted };
    Pop pop(SharedMemoryMessage& message);

    /// Messages waiting, as the indices say (at most kSlots unless corrupted).
    uint32_t waiting() const { return head_ - tail_; }

private:
    // Each index is written by one side only, and read by the other.
    volatile uint32_t head_ = 0; // Written by the writer.
    volatile uint32_t tail_ = 0; // Written by the reader.
    SharedMemoryMessage slots_[kSlots] = {};
};

} // namespace bsp
