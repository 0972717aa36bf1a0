#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/StackArena.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/Paging.hpp>

namespace dcos::internal {

namespace {

// A free block records its size and the next free block in its first bytes.
// Free blocks are present memory: a guard page is made present again before
// its block joins the free list.
struct FreeBlock {
    size_t size;
    FreeBlock* next;
};

static_assert(kStackArenaBytes % StackArena::kPageSize == 0, "the stack arena is whole pages");
static_assert(StackArena::kPageSize == arch_x86::Paging::kPageSize);

alignas(StackArena::kPageSize) uint8_t arena[kStackArenaBytes];
FreeBlock* freeList = nullptr;
bool initialised = false;

void initialiseOnce()
{
    if (!initialised) {
        freeList = reinterpret_cast<FreeBlock*>(arena);
        freeList->size = sizeof arena;
        freeList->next = nullptr;
        initialised = true;
    }
}

uint8_t* takeBlock(size_t size)
{
    FreeBlock** link = &freeList;
    for (FreeBlock* block = freeList; block != nullptr; link = &block->next, block = block->next) {
        if (block->size < size) {
            continue;
        }
        // Take the block's top end, so the free block keeps its place in the
        // list. Sizes are whole pages, so any remainder can stay a free
        // block: a block is never handed out larger than asked, which
        // release() relies on.
        if (block->size > size) {
            block->size -= size;
            return reinterpret_cast<uint8_t*>(block) + block->size;
        }
        *link = block->next;
        return reinterpret_cast<uint8_t*>(block);
    }
    return nullptr;
}

} // namespace

Result<uint8_t*> StackArena::allocate(size_t size)
{
    if (size == 0 || size > kStackArenaBytes) {
        return Status::NoMemory;
    }
    arch_x86::InterruptGuard guard;
    initialiseOnce();
    uint8_t* block = takeBlock(blockSize(size));
    if (block == nullptr) {
        return Status::NoMemory;
    }
    arch_x86::Paging::setPresent(reinterpret_cast<uintptr_t>(block), false);
    return block + kPageSize;
}

void StackArena::release(uint8_t* stack, size_t size)
{
    arch_x86::InterruptGuard guard;
    uint8_t* memory = stack - kPageSize;
    // The guard page becomes ordinary free memory again; the free list's
    // header is written into it just below.
    arch_x86::Paging::setPresent(reinterpret_cast<uintptr_t>(memory), true);
    auto* block = reinterpret_cast<FreeBlock*>(memory);
    block->size = blockSize(size);
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

bool StackArena::isGuardOf(const uint8_t* stack, uintptr_t address)
{
    const uintptr_t base = reinterpret_cast<uintptr_t>(stack);
    return stack != nullptr && address < base && address >= base - kPageSize;
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
