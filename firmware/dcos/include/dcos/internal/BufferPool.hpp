// The algorithm of a buffer pool (seed 7.7), free of kernel and hardware.
//
// A pool manages an area the caller supplies:
//
//     | state[0] ... state[n-1] | pad to 8 | buffer 0 | buffer 1 | ... | buffer n-1 |
//
// Each buffer has a 32-bit state word in the table at the start of the area:
// its low half is the holder (a 16-bit tag the kernel derives from the task
// id, kSystemHolder for the system, kFreeMark for a free buffer) and its high
// half a check value computed from the pool's salt, the buffer's index, the
// state and the holder. Free buffers form a LIFO list threaded through their
// first word: the next buffer's index in the low half and a check value in
// the high half. Allocate pops the head and Return pushes onto it, so both
// cost O(1), and both verify every word they read before they write any:
//
// - a buffer is handed out only if its state word says free, and is marked
//   allocated before it leaves, so a forged or looping free list can never
//   hand out memory twice; it is detected as corruption instead;
// - a buffer whose state word already says free is a double return;
// - a link or state word that fails its check was overwritten by the
//   application (typically a write into a buffer after returning it).
//
// Once corruption is found the pool is disabled: every call fails with
// Status::Corrupted until the owner deletes it. A check value has 16 bits,
// so a random overwrite escapes detection with probability 2^-16 per word.
//
// The class does no locking; its owner serialises calls.
#pragma once

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// A pool of fixed-size buffers in a caller-supplied contiguous area.
class BufferPool {
public:
    /// The holder tag of buffers that belong to the system: any holder may return them.
    static constexpr uint16_t kSystemHolder = 0xFFFF;
    /// Reserved: the holder field of a free buffer; never a valid holder.
    static constexpr uint16_t kFreeMark = 0xFFFE;
    /// Smallest buffer size, in bytes.
    static constexpr size_t kMinimumBufferSize = BufferPoolAgent::kMinimumBufferSize;
    /// Most buffers one pool can hold (16-bit indices, one value marks the list's end).
    static constexpr size_t kMaximumBuffers = BufferPoolAgent::kMaximumBuffers;

    /// Creates an unused pool; initialise() puts it in service.
    constexpr BufferPool() = default;

    /// Lays out a pool of as many @p bufferSize byte buffers as fit in
    /// @p areaBytes bytes at @p area, all free. O(buffers).
    ///
    /// @p salt makes the check values of this pool differ from those of
    /// any other (the kernel passes a fresh value per pool). Fails with
    /// InvalidArgument for a null area, a buffer size below 4, no buffer
    /// fitting, or more than kMaximumBuffers fitting; the pool is then unused.
    Status initialise(void* area, size_t areaBytes, size_t bufferSize, uint32_t salt);

    /// Takes the buffer at the head of the free list for @p holder. O(1).
    ///
    /// Fails with NoMemory when none is free, Corrupted when the pool is or
    /// turns out to be corrupted, and InvalidArgument for the reserved
    /// holder kFreeMark.
    Result<void*> allocate(uint16_t holder);

    /// Returns @p buffer on behalf of @p holder. O(1).
    ///
    /// InvalidArgument for a pointer outside the buffers; NotOwner when the
    /// buffer is held by another holder than @p holder or the system;
    /// Corrupted (the pool is disabled) for a free buffer, a pointer that is
    /// not a buffer's start, or a state word that fails its check.
    Status release(void* buffer, uint16_t holder);

    /// Hands @p buffer, held by @p from or by the system, to the holder @p to. O(1).
    ///
    /// Fails as release() does; InvalidArgument for the holder kFreeMark.
    Status transfer(void* buffer, uint16_t from, uint16_t to);

    /// Returns every buffer @p holder holds; returns how many. O(buffers).
    ///
    /// Resource recovery calls this when a task ends. When a state word
    /// fails its check the pool is disabled and the walk stops.
    size_t reclaimHeldBy(uint16_t holder);

    /// Checks the whole pool: every state word, and a free list that holds
    /// exactly the free buffers, each once. O(buffers).
    ///
    /// Returns Ok or Corrupted (and disables the pool). The kernel does not
    /// need it on any path; tests and diagnostics use it.
    Status audit();

    /// The pool's usage counters. O(1).
    BufferPoolStatistics statistics() const;

    /// Number of buffers currently allocated. O(1).
    size_t allocatedCount() const { return count_ - free_; }
    /// Whether a check failed; a corrupted pool refuses every call.
    bool isCorrupted() const { return corrupted_; }
    /// Whether initialise() succeeded and the pool has buffers.
    bool inService() const { return count_ != 0; }
    /// The first byte of the area given to initialise().
    uintptr_t areaBegin() const { return areaBegin_; }
    /// One past the last byte of the area given to initialise().
    uintptr_t areaEnd() const { return areaEnd_; }
    /// The holder of the buffer with index @p index, or kFreeMark when it is
    /// free; false when the index is out of range or its state word fails its check.
    bool holderOf(size_t index, uint16_t& holder) const;
    /// Number of buffers.
    size_t bufferCount() const { return count_; }
    /// Address of the buffer with index @p index.
    void* bufferAt(size_t index) const { return buffers_ + index * stride_; }

private:
    static constexpr uint16_t kEndOfList = 0xFFFF;

    enum class State : uint8_t { Free, Allocated, Invalid };

    uint16_t seal(uint32_t kind, uint32_t index, uint32_t value) const;
    uint32_t freeWord(uint32_t index) const;
    uint32_t allocatedWord(uint32_t index, uint16_t holder) const;
    uint32_t linkWord(uint32_t index, uint16_t next) const;
    State stateOf(uint32_t index, uint16_t& holder) const;
    // Finds the index of an allocated buffer for release() and transfer();
    // fails (disabling the pool where the seed asks for it) otherwise.
    Result<uint32_t> allocatedIndexOf(void* buffer, uint16_t holder);
    void pushFree(uint32_t index);
    Status fail();

    uint8_t* states_ = nullptr; // The state table: one 32-bit word per buffer.
    uint8_t* buffers_ = nullptr;
    uintptr_t areaBegin_ = 0;
    uintptr_t areaEnd_ = 0;
    uint32_t bufferSize_ = 0;
    uint32_t stride_ = 0;
    uint32_t count_ = 0;
    uint32_t free_ = 0;
    uint32_t lowWater_ = 0;
    uint32_t allocations_ = 0;
    uint32_t failedAllocations_ = 0;
    uint32_t returns_ = 0;
    uint32_t salt_ = 0;
    uint16_t head_ = kEndOfList;
    bool corrupted_ = false;
};

/// value * factor, as one IMUL on the board. Tuned for the i486, GCC spells
/// a multiplication by a constant as a chain of shifts, adds and LEAs: fewer
/// cycles there, but up to thirty instructions, on every check value a pool
/// or heap computes. Hiding the constant from the optimiser leaves the IMUL.
constexpr uint32_t multiplyWord(uint32_t value, uint32_t factor)
{
#ifndef DCOS_HOST_BUILD
    if (!__builtin_is_constant_evaluated()) {
        asm("" : "+r"(factor));
    }
#endif
    return value * factor;
}

/// Scrambles a 32-bit value (a finaliser with full avalanche); the check values of pools and heaps use it.
constexpr uint32_t mixBits(uint32_t value)
{
    value ^= value >> 16;
    value = multiplyWord(value, 0x7FEB352Du);
    value ^= value >> 15;
    value = multiplyWord(value, 0x846CA68Bu);
    value ^= value >> 16;
    return value;
}

} // namespace dcos::internal
