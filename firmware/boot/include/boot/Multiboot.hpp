// The Multiboot v1 hand-over (Multiboot Specification 0.6.96, 3.2 and 3.3):
// what a loader leaves for the kernel. QEMU's -kernel and GRUB fill it;
// the card's stage loader fills it the same way (StageLoader.cpp), and the
// kernel's entry reads it (MultibootEntry.cpp).
#pragma once

#include <stdint.h>

namespace boot::multiboot {

/// In EAX when the kernel starts (3.2).
constexpr uint32_t kLoaderMagic = 0x2BADB002;
/// Which fields of Info are valid (3.3).
constexpr uint32_t kInfoMemory = 1u << 0;
constexpr uint32_t kInfoCommandLine = 1u << 2;
constexpr uint32_t kInfoLoaderName = 1u << 9;

/// The information structure EBX points at (3.3).
struct Info {
    uint32_t flags;
    uint32_t memLower;
    uint32_t memUpper;
    uint32_t bootDevice;
    uint32_t cmdline;
    uint32_t modsCount;
    uint32_t modsAddr;
    uint32_t syms[4];
    uint32_t mmapLength;
    uint32_t mmapAddr;
    uint32_t drivesLength;
    uint32_t drivesAddr;
    uint32_t configTable;
    uint32_t bootLoaderName;
};

} // namespace boot::multiboot
