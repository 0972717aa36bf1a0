// The algorithm of a buffer pool (seed 7.7), free of kernel and hardware.
//
// A pool manages an area the caller supplies:
//
//     | state[0] ... state[n-1] | links[0] ... links[n-1] | pad to 8 | buffer 0 | ... | buffer n-1 |
//
// Each buffer has a 32-bit state word in the table at the start of the area.
// Its low half is the buffer's own index and its high half the holder (a
// 16-bit tag the kernel derives from the task id, kSystemHolder for the
// system) of an allocated buffer, or the index of the next free buffer of a
// free one, and the whole word is XORed with one of two per-pool keys, one
// for each state. So the free buffers form a LIFO list threaded through the
// state table, and the pool's bookkeeping lives in the state table only:
// nothing of it is kept inside the buffers, so a task writing into a buffer
// it has returned damages only its own data, never the pool.
//
// Allocate pops the head of the list and Return pushes onto it, so both cost
// O(1), and both check every word they read before they write any:
//
// - a buffer is handed out only if its state word decodes as free under the
//   free key with its own index, and is marked allocated before it leaves,
//   so a forged or looping free list can never hand out memory twice; it is
//   detected as corruption instead;
// - a buffer whose state word decodes as free is a double return;
// - a word that decodes as neither, or with another index, was overwritten
//   (a stray write into the state table, or a state word copied from another
//   buffer or pool).
//
// Once corruption is found the pool is disabled: every call fails with
// Status::Corrupted until the owner deletes it. The index half is the check:
// a random overwrite passes for one particular buffer with probability 2^-16.
//
// The common cases have inline fast paths, tryAllocate() and tryRelease(),
// which the kernel's services call directly: a pop (one state word read,
// checked, rewritten) and a push after a range and alignment test that
// takes one multiplication and one rotation (the stride's exact-division
// inverse, so no division). They handle only the case that succeeds; every
// other case, errors included, is left to allocate() and release(), which
// give the precise status. The cost of a fast path is the same whatever the
// pool holds.
//
// Each buffer also has two link words (HeldList.hpp), which the kernel uses
// to keep every task's list of the buffers it holds; the pool only lays them
// out and hands them over: tryAllocate() and tryRelease() give them to the
// caller's functor with the buffer's index, and linksOf() finds them.
//
// The class does no locking; its owner serialises calls.
#pragma once

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/internal/HeldList.hpp>
#include <dcos/Status.hpp>

#include <bit>
#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// A pool of fixed-size buffers in a caller-supplied contiguous area.
class BufferPool {
public:
    /// The holder tag of buffers that belong to the system: any holder may return them.
    static constexpr uint16_t kSystemHolder = 0xFFFF;
    /// Reserved: what holderOf() reports for a free buffer; never a valid holder.
    static constexpr uint16_t kFreeMark = 0xFFFE;
    /// The holder tag of buffers lent to a task of another node that shares
    /// this node's memory (RemoteMemoryHolds.hpp): only the remote agent,
    /// returning them for that node, holds this tag, so no task of this node
    /// can return such a buffer behind the other node's back. Never a task's.
    static constexpr uint16_t kLentHolder = 0xFFFD;
    /// Smallest buffer size, in bytes.
    static constexpr size_t kMinimumBufferSize = BufferPoolAgent::kMinimumBufferSize;
    /// Most buffers one pool can hold (16-bit indices, one value marks the list's end).
    static constexpr size_t kMaximumBuffers = BufferPoolAgent::kMaximumBuffers;

    /// The functor of tryAllocate() and tryRelease() for callers that keep no lists.
    struct IgnoreLinks {
        void operator()(uint32_t, uint8_t*) const {}
    };

    /// Creates an unused pool; initialise() puts it in service.
    constexpr BufferPool() = default;

    /// Lays out a pool of as many @p bufferSize byte buffers as fit in
    /// @p areaBytes bytes at @p area, all free. O(buffers).
    ///
    /// @p salt makes the state words of this pool differ from those of
    /// any other (the kernel passes a fresh value per pool). Fails with
    /// InvalidArgument for a null area, a buffer size below 4, no buffer
    /// fitting, or more than kMaximumBuffers fitting; the pool is then unused.
    Status initialise(void* area, size_t areaBytes, size_t bufferSize, uint32_t salt);

    /// The fast path of allocate(): takes the head of the free list for
    /// the holder in the low half of what @p holderWord() returns (a
    /// uint32_t whose high half is ignored, so the kernel may give a whole
    /// task id), or returns null when the list is empty, the pool is
    /// corrupted or the head's state word fails its check (allocate() then
    /// says which). The holder must not be kFreeMark. O(1).
    ///
    /// The holder is asked for only once the head passed its checks: while
    /// they run, the kernel's fast path has no register to spare for it.
    ///
    /// @p taken(index, links) is called with the buffer's index and its
    /// link words once it is the holder's, before it is returned. (The
    /// caller knows its holder; handing the word back made GCC keep a dead
    /// copy of it on the stack.)
    template <typename HolderWord, typename Taken = IgnoreLinks>
    [[gnu::always_inline]] void* tryAllocate(HolderWord holderWord, Taken taken = {})
    {
        const uint32_t index = head_;
        if (index >= limit_) {
            return nullptr; // Empty (kEndOfList), corrupted (limit_ 0) or a bad head.
        }
        // Decoded with the free key and XORed with its own index, the word
        // of a free buffer has a zero low half and the next index above it:
        // one XOR more saves isolating the half to compare it.
        const uint32_t word = loadState(index) ^ freeKey_ ^ index;
        if ((word & 0xFFFF) != 0) {
            return nullptr;
        }
        head_ = word >> 16; // Checked when it is the head: below limit_, or the end.
        const uint32_t holder = static_cast<uint32_t>(holderWord());
        storeState(index, ((holder << 16) | index) ^ allocatedKey_);
        taken(index, linksOf(index));
        // The free buffers are the low-water mark plus those above it, and
        // only when none is above it does the mark move. The test is a CMP
        // of the count in memory with 0 (isZero), the common case a DEC in
        // memory: three instructions where GCC's load, subtract, branch on
        // the borrow and store were four.
        if (isZero(aboveLowWater_)) [[unlikely]] {
            --lowWater_;
        } else {
            --aboveLowWater_;
        }
        ++allocations_;
        void* const buffer = reinterpret_cast<void*>(base_ + index * stride_);
        // A buffer lies inside a non-null area that does not wrap, so it is
        // never null: the caller's test of the result then costs nothing.
        if (buffer == nullptr) {
            __builtin_unreachable();
        }
        return buffer;
    }

    /// The fast path of release(): gives back @p buffer if it is the start
    /// of a buffer that the holder in the low half of what @p holderWord()
    /// returns itself holds (the high half is ignored, as for
    /// tryAllocate()); false in every other case (release() then decides).
    /// The holder is asked for once the address is known to be a buffer's,
    /// for the reason tryAllocate() gives. O(1).
    ///
    /// @p given(index, links) is called with the buffer's index and its link
    /// words once it is known to be the holder's, just after it is freed
    /// (its links are not touched by the freeing).
    template <typename HolderWord, typename Given = IgnoreLinks>
    [[gnu::always_inline]] bool tryRelease(void* buffer, HolderWord holderWord, Given given = {})
    {
        const uintptr_t index = indexOf(buffer);
        if (index >= limit_) {
            return false; // Not a buffer's start, not this pool's, or corrupted.
        }
        // The word it must hold, built before the load, so that no address
        // waits in a register while the holder is asked for.
        const uint32_t holder = static_cast<uint32_t>(holderWord());
        const uint32_t expected = ((holder << 16) | static_cast<uint32_t>(index)) ^ allocatedKey_;
        if (loadState(static_cast<uint32_t>(index)) != expected) {
            return false; // Free already, another holder's, the system's, or overwritten.
        }
        // Freed first: the state word's address then need not live on, in a
        // register or spilled, across the holder's list work, which reads
        // only the links.
        pushFree(static_cast<uint32_t>(index));
        given(static_cast<uint32_t>(index), linksOf(static_cast<uint32_t>(index)));
        return true;
    }

    /// Takes the buffer at the head of the free list for @p holder. O(1).
    /// Its link words are left for the caller (linksOf()).
    ///
    /// Fails with NoMemory when none is free, Corrupted when the pool is or
    /// turns out to be corrupted, and InvalidArgument for the reserved
    /// holder kFreeMark.
    Result<void*> allocate(uint16_t holder)
    {
        if (holder != kFreeMark) [[likely]] {
            if (void* buffer = tryAllocate([holder] { return uint32_t{holder}; })) [[likely]] {
                return buffer;
            }
        }
        return allocateSlowly(holder);
    }

    /// Returns @p buffer on behalf of @p holder. O(1).
    ///
    /// InvalidArgument for a pointer outside the buffers; NotOwner when the
    /// buffer is held by another holder than @p holder or the system;
    /// Corrupted (the pool is disabled) for a free buffer, a pointer that is
    /// not a buffer's start, or a state word that fails its check.
    Status release(void* buffer, uint16_t holder)
    {
        if (tryRelease(buffer, [holder] { return uint32_t{holder}; })) [[likely]] {
            return Status::Ok;
        }
        return releaseSlowly(buffer, holder);
    }

    /// Hands @p buffer, held by @p from or by the system, to the holder @p to. O(1).
    ///
    /// Fails as release() does; InvalidArgument for the holder kFreeMark.
    /// On success @p moved(index, links, previousHolder) is called, with
    /// previousHolder @p from or kSystemHolder.
    template <typename Moved>
    Status transfer(void* buffer, uint16_t from, uint16_t to, Moved moved)
    {
        uint16_t previous = kSystemHolder;
        const Status status = transferIndex(buffer, from, to, previous);
        if (status == Status::Ok) {
            const uint32_t index = indexOfBuffer(buffer);
            moved(index, linksOf(index), previous);
        }
        return status;
    }
    /// transfer() for callers that keep no lists.
    Status transfer(void* buffer, uint16_t from, uint16_t to)
    {
        return transfer(buffer, from, to, [](uint32_t, uint8_t*, uint16_t) {});
    }

    /// Frees the buffer with index @p index if @p holder holds it; false
    /// (nothing changed) if not, or if the index is out of range. Recovery
    /// uses it on the items of a dead task's list. O(1).
    bool reclaim(uint32_t index, uint16_t holder);

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
    size_t allocatedCount() const { return count_ - freeCount(); }
    /// Whether a check failed; a corrupted pool refuses every call.
    bool isCorrupted() const { return limit_ == 0 && count_ != 0; }
    /// Whether initialise() succeeded and the pool has buffers.
    bool inService() const { return count_ != 0; }
    /// The holder of the buffer with index @p index, or kFreeMark when it is
    /// free; false when the index is out of range or its state word fails its check.
    bool holderOf(size_t index, uint16_t& holder) const;
    /// Number of buffers.
    size_t bufferCount() const { return count_; }
    /// Address of the buffer with index @p index.
    void* bufferAt(size_t index) const { return reinterpret_cast<void*>(base_ + index * stride_); }
    /// The index of the buffer starting at @p buffer; bufferCount() or more
    /// for any other address. O(1).
    uint32_t indexOfBuffer(const void* buffer) const
    {
        const uintptr_t index = indexOf(buffer);
        return index < count_ ? static_cast<uint32_t>(index) : count_;
    }
    /// The link words of the buffer with index @p index (below bufferCount()).
    uint8_t* linksOf(uint32_t index) const { return links_ + index * HeldLinks::kBytes; }
    /// linksOf(), or null when the index is out of range or the pool is
    /// corrupted or out of service: for resolving a held list's handles. O(1).
    uint8_t* linksIfInService(uint32_t index) const { return index < limit_ ? linksOf(index) : nullptr; }

private:
    static constexpr uint32_t kEndOfList = 0xFFFF;

    enum class State : uint8_t { Free, Allocated, Invalid };

    // The area belongs to the application, which may declare it as bytes of
    // any type; words are therefore moved with memcpy, which the compiler
    // turns into a single load or store and which is valid whatever the
    // declared type.
    uint32_t loadState(uint32_t index) const
    {
        uint32_t word;
        __builtin_memcpy(&word, states_ + index * 4, sizeof word);
        return word;
    }
    void storeState(uint32_t index, uint32_t word) { __builtin_memcpy(states_ + index * 4, &word, sizeof word); }

    // The index of the buffer starting at @p buffer; count_ or more for any
    // other address, inside the pool or not. offset / stride_ exactly, by
    // the multiplicative inverse of the stride's odd part and a rotation by
    // its power of two: the result is the quotient when the stride divides
    // the offset, and above every buffer index when it does not (Granlund
    // and Montgomery's divisibility test).
    uintptr_t indexOf(const void* buffer) const
    {
        return std::rotr((reinterpret_cast<uintptr_t>(buffer) - base_) * inverse_, int{shift_});
    }

    // Whether @p count is 0, as a CMP of it in memory with 0 and the zero
    // flag as the result: for a comparison with 0 GCC loads the word and
    // tests the register instead, one instruction more.
    [[gnu::always_inline]] static bool isZero(const uint32_t& count)
    {
#if defined(__i386__) || defined(__x86_64__)
        bool zero;
        asm("cmpl $0, %1" : "=@cce"(zero) : "m"(count));
        return zero;
#else
        return count == 0;
#endif
    }

    void pushFree(uint32_t index)
    {
        storeState(index, ((head_ << 16) | index) ^ freeKey_);
        head_ = index;
        ++aboveLowWater_;
    }

    // The free buffers: the low-water mark and how many are above it
    // (kept so, Allocate keeps the mark with one subtraction).
    uint32_t freeCount() const { return lowWater_ + aboveLowWater_; }

    State stateOf(uint32_t index, uint16_t& holder, uint32_t& next) const;
    Result<void*> allocateSlowly(uint16_t holder);
    Status releaseSlowly(void* buffer, uint16_t holder);
    // Finds the index of an allocated buffer for release() and transfer();
    // fails (disabling the pool where the seed asks for it) otherwise.
    Result<uint32_t> allocatedIndexOf(void* buffer, uint16_t holder);
    Status transferIndex(void* buffer, uint16_t from, uint16_t to, uint16_t& previous);
    Status fail();

    uint8_t* states_ = nullptr; // The state table: one 32-bit word per buffer, then the links.
    uintptr_t base_ = 0;        // The first buffer.
    uint32_t stride_ = 0;
    uintptr_t inverse_ = 0;     // Of the stride's odd part, modulo 2^32 (2^64 on a 64-bit host).
    uint8_t shift_ = 0;         // The stride's trailing zero bits.
    uint8_t sizeSlack_ = 0;     // The stride less the buffer size (0 to 3).
    // count_ while in service, 0 once corrupted (which is how isCorrupted()
    // tells): the fast paths' one test.
    uint32_t limit_ = 0;
    uint32_t head_ = kEndOfList;
    uint32_t aboveLowWater_ = 0; // Free buffers above the low-water mark.
    uint32_t lowWater_ = 0;      // The fewest free buffers there have been.
    uint32_t allocations_ = 0;
    uint32_t freeKey_ = 0;      // Every free buffer's state word is XORed with it,
    uint32_t allocatedKey_ = 0; // every allocated buffer's with this one.
    uint32_t count_ = 0;
    uint32_t failedAllocations_ = 0;
    uint8_t* links_ = nullptr; // The held-list links, after the state words.
    // Sixty bytes on the board: with the kernel's id beside it, a pool slot
    // is 64 bytes (BufferPoolManager.cpp). The area's bounds are the
    // kernel's to keep.
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
