// The static memory task stacks are carved from.
//
// Creating and deleting tasks are configuration-class services (seed 6.4), so
// a first-fit search over a free list is acceptable here; nothing on a
// real-time path allocates. Free blocks are kept in address order and merged
// with both neighbours when returned, so the arena does not fragment into
// unusable slivers as tasks come and go.
#pragma once

#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

class StackArena {
public:
    /// Stacks are 16-byte aligned, as the i386 System V ABI expects.
    static constexpr size_t kAlignment = 16;

    /// Takes size bytes (rounded up); NoMemory when no free block is large enough.
    static Result<uint8_t*> allocate(size_t size);
    /// Returns a block from allocate().
    static void release(uint8_t* block, size_t size);
    /// Bytes free and the largest free block, for diagnostics.
    static size_t freeBytes();
    static size_t largestFreeBlock();
};

} // namespace dcos::internal
