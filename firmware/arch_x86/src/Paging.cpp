#include <arch_x86/Paging.hpp>

namespace arch_x86 {

namespace {

// Page directory and page table entry bits (Intel SDM Vol. 3, 4.3, Tables
// 4-5 and 4-6): present, writable, supervisor only. Only ring 0 runs today;
// the user bit stays clear until the protection work (roadmap 10) gives
// tasks their own rings.
constexpr uint32_t entryPresent = 1u << 0;
constexpr uint32_t entryWritable = 1u << 1;
// Page-level write-through and cache disable (SDM Vol. 3, 4.9 and 11.12):
// a device register is never served from the cache.
constexpr uint32_t entryWriteThrough = 1u << 3;
constexpr uint32_t entryCacheDisable = 1u << 4;
constexpr uint32_t entryFrameMask = 0xFFFFF000u;

constexpr uintptr_t entriesPerTable = 1024;
constexpr uintptr_t bytesPerTable = entriesPerTable * Paging::kPageSize; // 4 MiB

// CR0.PG (SDM Vol. 3, 2.5): paging on.
constexpr uint32_t cr0Paging = 1u << 31;

uint32_t* directoryTable = nullptr;
uintptr_t mappedLimit = 0;

uint32_t* tableEntryFor(uintptr_t address)
{
    if (directoryTable == nullptr || address >= mappedLimit) {
        return nullptr;
    }
    auto* table = reinterpret_cast<uint32_t*>(directoryTable[address / bytesPerTable] & entryFrameMask);
    return &table[(address / Paging::kPageSize) % entriesPerTable];
}

} // namespace

uintptr_t Paging::enable(uintptr_t memoryEnd, uintptr_t tablesStart)
{
    memoryEnd = pageBase(memoryEnd);
    tablesStart = roundUpToPage(tablesStart);
    const uintptr_t tableCount = (memoryEnd + bytesPerTable - 1) / bytesPerTable;

    directoryTable = reinterpret_cast<uint32_t*>(tablesStart);
    auto* tables = reinterpret_cast<uint32_t*>(tablesStart + kPageSize);
    for (uintptr_t i = 0; i < entriesPerTable; ++i) {
        directoryTable[i] = 0;
    }
    for (uintptr_t t = 0; t < tableCount; ++t) {
        uint32_t* table = tables + t * entriesPerTable;
        for (uintptr_t i = 0; i < entriesPerTable; ++i) {
            const uintptr_t address = t * bytesPerTable + i * kPageSize;
            table[i] = address < memoryEnd ? static_cast<uint32_t>(address) | entryPresent | entryWritable : 0;
        }
        directoryTable[t] = static_cast<uint32_t>(reinterpret_cast<uintptr_t>(table)) | entryPresent | entryWritable;
    }
    mappedLimit = memoryEnd;
    // Page 0 stays out, so that a null pointer (and any small offset from
    // one) faults instead of reading the real-mode interrupt vectors.
    tables[0] = 0;

    asm volatile("movl %0, %%cr3" : : "r"(static_cast<uint32_t>(tablesStart)) : "memory");
    uint32_t cr0;
    asm volatile("movl %%cr0, %0" : "=r"(cr0));
    // The jump after setting PG is what the i486 needs to discard what it
    // prefetched (SDM Vol. 3, 9.9.1); identity mapping keeps EIP valid.
    asm volatile("movl %0, %%cr0\n\t"
                 "jmp 1f\n"
                 "1:"
                 :
                 : "r"(cr0 | cr0Paging)
                 : "memory");
    return tablesStart + kPageSize + tableCount * kPageSize;
}

bool Paging::mapDevice(uintptr_t physical, size_t bytes)
{
    // The one table of device pages, and the 4 MiB region it serves once
    // the first device is mapped.
    alignas(kPageSize) static uint32_t deviceTable[entriesPerTable];
    static uintptr_t deviceRegion = 0;

    if (directoryTable == nullptr || bytes == 0 || physical < mappedLimit || physical + (bytes - 1) < physical) {
        return false;
    }
    const uintptr_t first = pageBase(physical);
    const uintptr_t last = pageBase(physical + (bytes - 1));
    const uintptr_t region = first / bytesPerTable;
    if (last / bytesPerTable != region || (deviceRegion != 0 && deviceRegion != region)) {
        return false;
    }
    if (deviceRegion == 0) {
        if ((directoryTable[region] & entryPresent) != 0) {
            return false; // The memory's own tables reach that far.
        }
        deviceRegion = region;
        directoryTable[region] =
            static_cast<uint32_t>(reinterpret_cast<uintptr_t>(deviceTable)) | entryPresent | entryWritable;
    }
    for (uintptr_t page = first; page <= last; page += kPageSize) {
        deviceTable[(page / kPageSize) % entriesPerTable] =
            static_cast<uint32_t>(page) | entryPresent | entryWritable | entryWriteThrough | entryCacheDisable;
        asm volatile("invlpg (%0)" : : "r"(page) : "memory");
    }
    return true;
}

void Paging::setPresent(uintptr_t page, bool present)
{
    uint32_t* entry = tableEntryFor(page);
    if (entry == nullptr || pageBase(page) == 0) {
        return; // Page 0 never comes back.
    }
    const uint32_t frame = static_cast<uint32_t>(pageBase(page));
    *entry = present ? frame | entryPresent | entryWritable : frame;
    // INVLPG is an i486 instruction (SDM Vol. 2A).
    asm volatile("invlpg (%0)" : : "r"(page) : "memory");
}

bool Paging::isPresent(uintptr_t address)
{
    const uint32_t* entry = tableEntryFor(address);
    return entry != nullptr && (*entry & entryPresent) != 0;
}

bool Paging::enabled() { return directoryTable != nullptr; }

uintptr_t Paging::mappedEnd() { return mappedLimit; }

uint32_t Paging::directory() { return static_cast<uint32_t>(reinterpret_cast<uintptr_t>(directoryTable)); }

} // namespace arch_x86
