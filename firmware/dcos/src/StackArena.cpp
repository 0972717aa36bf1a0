#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/StackArena.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/Paging.hpp>

namespace dcos::internal {

namespace {

// A free block records its size and its neighbours in the free list in its
// first bytes. Free blocks are present memory: a guard page is made present
// again before its block joins the free list.
struct FreeBlock {
    size_t size;
    FreeBlock* next;
    FreeBlock* previous;
};

static_assert(kStackArenaBytes % StackArena::kPageSize == 0, "the stack arena is whole pages");
static_assert(StackArena::kPageSize == arch_x86::Paging::kPageSize);

constexpr size_t kPages = kStackArenaBytes / StackArena::kPageSize;
static_assert(kPages < 0xFFFF, "page tags are 16 bits");

alignas(StackArena::kPageSize) uint8_t arena[kStackArenaBytes];
FreeBlock* freeList = nullptr;
bool initialised = false;

// Boundary tags, kept beside the arena because a stack's first page is its
// guard, which is not present while the stack is in use: the tags of a
// block cannot live in the block. For every free block, its first page's
// entry in lastPagePlusOne names its last page, and its last page's entry in
// firstPagePlusOne names its first page (both plus one; zero means "not
// the first, or last, page of a free block"). release() finds the free
// neighbours of a returned block by looking up the page after it and the
// page before it, so it costs the same whatever the free list holds: a
// task's death recovers its stack in constant time, with interrupts held
// off for constant time, however fragmented the arena. 4 bytes a page.
uint16_t lastPagePlusOne[kPages];
uint16_t firstPagePlusOne[kPages];

size_t pageOf(const void* address)
{
    return static_cast<size_t>(static_cast<const uint8_t*>(address) - arena) / StackArena::kPageSize;
}

FreeBlock* blockAtPage(size_t page) { return reinterpret_cast<FreeBlock*>(arena + page * StackArena::kPageSize); }

// Records block, of its current size, as free in the tags.
void tag(FreeBlock* block)
{
    const size_t first = pageOf(block);
    const size_t last = first + block->size / StackArena::kPageSize - 1;
    lastPagePlusOne[first] = static_cast<uint16_t>(last + 1);
    firstPagePlusOne[last] = static_cast<uint16_t>(first + 1);
}

// Removes block's tags (before it grows, shrinks, merges or is taken).
void untag(FreeBlock* block)
{
    const size_t first = pageOf(block);
    const size_t last = first + block->size / StackArena::kPageSize - 1;
    lastPagePlusOne[first] = 0;
    firstPagePlusOne[last] = 0;
}

void link(FreeBlock* block)
{
    block->previous = nullptr;
    block->next = freeList;
    if (freeList != nullptr) {
        freeList->previous = block;
    }
    freeList = block;
}

void unlink(FreeBlock* block)
{
    if (block->previous != nullptr) {
        block->previous->next = block->next;
    } else {
        freeList = block->next;
    }
    if (block->next != nullptr) {
        block->next->previous = block->previous;
    }
}

void initialiseOnce()
{
    if (!initialised) {
        FreeBlock* const whole = reinterpret_cast<FreeBlock*>(arena);
        whole->size = sizeof arena;
        link(whole);
        tag(whole);
        initialised = true;
    }
}

uint8_t* takeBlock(size_t size)
{
    // First fit: Create is a configuration service, allowed to search.
    for (FreeBlock* block = freeList; block != nullptr; block = block->next) {
        if (block->size < size) {
            continue;
        }
        untag(block);
        // Take the block's top end, so the free block keeps its header and
        // its place in the list. Sizes are whole pages, so any remainder
        // can stay a free block: a block is never handed out larger than
        // asked, which release() relies on.
        if (block->size > size) {
            block->size -= size;
            tag(block);
            return reinterpret_cast<uint8_t*>(block) + block->size;
        }
        unlink(block);
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
    // The guard page becomes ordinary free memory again; the free block's
    // header is written into it just below.
    arch_x86::Paging::setPresent(reinterpret_cast<uintptr_t>(memory), true);
    auto* block = reinterpret_cast<FreeBlock*>(memory);
    block->size = blockSize(size);
    const size_t first = pageOf(block);
    const size_t after = first + block->size / kPageSize;
    // A free block right after this one joins it.
    if (after < kPages && lastPagePlusOne[after] != 0) {
        FreeBlock* const next = blockAtPage(after);
        untag(next);
        unlink(next);
        block->size += next->size;
    }
    // A free block right before this one takes it in, keeping its header.
    if (first > 0 && firstPagePlusOne[first - 1] != 0) {
        FreeBlock* const previous = blockAtPage(firstPagePlusOne[first - 1] - 1u);
        untag(previous);
        previous->size += block->size;
        tag(previous);
        return;
    }
    link(block);
    tag(block);
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
