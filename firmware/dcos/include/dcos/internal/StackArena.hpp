// The static memory task stacks are carved from.
//
// Creating tasks is a configuration-class service (seed 6.4), so a first-fit
// search over a free list is acceptable for allocate(); nothing on a
// real-time path allocates. Returning a stack is part of a task's death,
// whose recovery must cost what the task owned, never what the arena holds
// (issue 12): release() finds a block's free neighbours through boundary
// tags kept beside the arena, merges with both in constant time, and so
// the arena does not fragment into unusable slivers as tasks come and go.
//
// Every stack is whole pages with a guard page below it that is not present
// (arch_x86/Paging.hpp): a task that runs off the bottom of its stack faults
// on the guard instead of writing over the stack below, which belongs to
// another task. A stack of n bytes therefore takes the pages n rounds up
// to, plus one.
#pragma once

#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

class StackArena {
public:
    /// The page size of the guards and of the stacks' rounding.
    static constexpr size_t kPageSize = 4096;
    /// Stacks start on a page, which more than meets the i386 System V
    /// ABI's 16-byte alignment.
    static constexpr size_t kAlignment = kPageSize;

    /// The bytes a task asking for size bytes of stack gets: whole pages.
    static constexpr size_t usableSize(size_t size)
    {
        return size > SIZE_MAX - kPageSize ? SIZE_MAX & ~(kPageSize - 1) : (size + kPageSize - 1) & ~(kPageSize - 1);
    }
    /// The arena bytes such a stack takes: its pages and its guard page.
    static constexpr size_t blockSize(size_t size)
    {
        return usableSize(size) > SIZE_MAX - kPageSize ? SIZE_MAX : usableSize(size) + kPageSize;
    }

    /// Takes a stack of usableSize(size) bytes, its guard page below it
    /// made not present, and returns its lowest byte; NoMemory when no free
    /// block is large enough.
    static Result<uint8_t*> allocate(size_t size);
    /// Returns a stack from allocate(), with the size it was asked for. Cost O(1).
    static void release(uint8_t* stack, size_t size);
    /// Whether address lies in the guard page below stack.
    static bool isGuardOf(const uint8_t* stack, uintptr_t address);
    /// Bytes free and the largest free block, for diagnostics.
    static size_t freeBytes();
    static size_t largestFreeBlock();
};

} // namespace dcos::internal
