// Two-level i386 paging as DCOS uses it: an identity map of the board's
// memory with holes where a touch must fault.
//
// DCOS runs every task in one address space, so paging is not there to
// translate addresses but to catch the faults a control system must not let
// pass silently (Intel SDM Vol. 3, 4.3, "32-bit paging", which the i486
// already has):
//   - page 0 is not present, so a null pointer access faults at once;
//   - the page below every task stack is not present (a guard page), so a
//     stack overflow faults on its first touch instead of corrupting the
//     neighbouring stack.
// Virtual and physical addresses stay equal, so nothing else in the kernel
// changes, and the page tables live in the first free memory above the
// image, sized for the memory the loader reported.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace arch_x86 {

class Paging {
public:
    /// The page size of 32-bit paging (SDM Vol. 3, 4.3).
    static constexpr uintptr_t kPageSize = 4096;

    static constexpr uintptr_t pageBase(uintptr_t address) { return address & ~(kPageSize - 1); }
    static constexpr uintptr_t roundUpToPage(uintptr_t size) { return (size + kPageSize - 1) & ~(kPageSize - 1); }

#if defined(DCOS_HOST_BUILD)
    // Host unit tests have no MMU: guards are only recorded, so portable
    // code (the stack arena) can be tested against the calls it makes.
    static void setPresent(uintptr_t page, bool present);
    static bool isPresent(uintptr_t address);
#else
    /// Builds the identity map of [0, memoryEnd) with page 0 not present,
    /// placing the page directory and tables at tablesStart (page aligned,
    /// in free memory), loads CR3 and turns paging on. Returns the first
    /// address after the tables. Called once at boot, before any task.
    static uintptr_t enable(uintptr_t memoryEnd, uintptr_t tablesStart);

    /// Makes one page present or not present and flushes its translation.
    /// Addresses outside the mapped memory are ignored. O(1).
    static void setPresent(uintptr_t page, bool present);

    /// Whether the page holding address is mapped and present.
    static bool isPresent(uintptr_t address);

    /// Maps the device registers at [physical, physical + bytes) above the
    /// memory, identity, writable and uncached (PCD and PWT: a register read
    /// must reach the device every time). The local and I/O APICs of the
    /// dual-Pentium board live there. Every device page must lie in one
    /// 4 MiB region above mappedEnd(), served by one page table in static
    /// storage: false (nothing changed) for a range outside it, inside the
    /// memory, or before paging is on. The ISA board never calls it, and the
    /// linker leaves its table out of that image.
    static bool mapDevice(uintptr_t physical, size_t bytes);

    /// Whether paging has been turned on.
    static bool enabled();

    /// The end of the identity-mapped memory.
    static uintptr_t mappedEnd();

    /// The physical address of the page directory, for CR3 and the TSSs.
    static uint32_t directory();
#endif
};

} // namespace arch_x86
