#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/StackArena.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos::internal {

namespace {

// A free block records its size and the next free block in its first bytes.
struct FreeBlock {
    size_t size;
    FreeBlock* next;
};

alignas(StackArena::kAlignment) uint8_t arena[kStackArenaBytes];
FreeBlock* freeList = nullptr;
bool initialised = false;

static_assert(sizeof(FreeBlock) <= StackArena::kAlignment, "every remainder must hold a free block header");

size_t roundUp(size_t size) { return (size + StackArena::kAlignment - 1) & ~(StackArena::kAlignment - 1); }

void initialiseOnce()
{
    if (!initialised) {
        freeList = reinterpret_cast<FreeBlock*>(arena);
        freeList->size = sizeof arena;
        freeList->next = nullptr;
        initialised = true;
    }
}

} // namespace

Result<uint8_t*> StackArena::allocate(size_t size)
{
    arch_x86::InterruptGuard guard;
    initialiseOnce();
    size = roundUp(size < sizeof(FreeBlock) ? sizeof(FreeBlock) : size);
    FreeBlock** link = &freeList;
    for (FreeBlock* block = freeList; block != nullptr; link = &block->next, block = block->next) {
        if (block->size < size) {
            continue;
        }
        // Take the block's top end, so the free block keeps its place in the
        // list. Sizes are multiples of the alignment, which a free block's
        // header fits in, so any remainder can stay a free block: a block
        // is never handed out larger than asked, which release() relies on.
        if (block->size > size) {
            block->size -= size;
            return reinterpret_cast<uint8_t*>(block) + block->size;
        }
        *link = block->next;
        return reinterpret_cast<uint8_t*>(block);
    }
    return Status::NoMemory;
}

void StackArena::release(uint8_t* memory, size_t size)
{
    arch_x86::InterruptGuard guard;
    size = roundUp(size < sizeof(FreeBlock) ? sizeof(FreeBlock) : size);
    auto* block = reinterpret_cast<FreeBlock*>(memory);
    block->size = size;
    // Find the neighbours in address order.
    FreeBlock* previous = nullptr;
    FreeBlock* next = freeList;
    while (next != nullptr && next < block) {
        previous = next;
        next = next->next;
    }
    block->next = next;
    if (previous != nullptr) {
        previous->next = block;
    } else {
        freeList = block;
    }
    // Merge with the following block, then with the preceding one.
    if (next != nullptr && reinterpret_cast<uint8_t*>(block) + block->size == reinterpret_cast<uint8_t*>(next)) {
        block->size += next->size;
        block->next = next->next;
    }
    if (previous != nullptr &&
        reinterpret_cast<uint8_t*>(previous) + previous->size == reinterpret_cast<uint8_t*>(block)) {
        previous->size += block->size;
        previous->next = block->next;
    }
}

size_t StackArena::freeBytes()
{
    arch_x86::InterruptGuard guard;
    initialiseOnce();
    size_t total = 0;
    for (FreeBlock* block = freeList; block != nullptr; block = block->next) {
        total += block->size;
    }
    return total;
}

size_t StackArena::largestFreeBlock()
{
    arch_x86::InterruptGuard guard;
    initialiseOnce();
    size_t largest = 0;
    for (FreeBlock* block = freeList; block != nullptr; block = block->next) {
        largest = block->size > largest ? block->size : largest;
    }
    return largest;
}

} // namespace dcos::internal
