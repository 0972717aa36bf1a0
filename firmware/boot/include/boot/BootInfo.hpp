// What the boot loader tells the kernel, in a loader-neutral form.
//
// The Multiboot entry fills this today; the disk/CompactFlash boot path will
// fill the same structure, so the kernel never sees a loader's own format.
#pragma once

#include <stdint.h>

namespace boot {

struct BootInfo {
    /// Conventional memory below 1 MiB, in KiB.
    uint32_t lowerMemoryKib = 0;
    /// Contiguous memory from 1 MiB up, in KiB.
    uint32_t upperMemoryKib = 0;
    /// The kernel command line, never null ("" when none was given).
    const char* commandLine = "";
    /// Name of the loader that started the node, for the version report.
    const char* loaderName = "unknown";
};

/// Looks up "key=value" in a space-separated command line. Copies the value
/// (at most capacity - 1 characters, always terminated) and returns true if
/// the key is present; a bare "key" yields an empty value.
bool findCommandLineOption(const char* commandLine, const char* key, char* value, uint32_t capacity);

/// Reads a node id written as "node=" takes it: 1 to 65534 in decimal, at
/// most five digits, nothing else. False (and @p node unchanged) otherwise.
bool parseNodeId(const char* text, uint16_t& node);

/// The image's extent in memory, from the linker script.
struct ImageLayout {
    uintptr_t start;
    uintptr_t end;
    uintptr_t bssStart;
    uintptr_t bssEnd;
    uintptr_t bootStackBottom;
    uintptr_t bootStackTop;
};

ImageLayout imageLayout();

} // namespace boot

/// The loader-independent kernel entry. It never returns.
[[noreturn]] void kernelMain(const boot::BootInfo& bootInfo);

namespace dcos {
/// What the loader told the kernel (a copy kernelMain keeps): the command
/// line and the memory, for any part of the kernel that reads them.
const boot::BootInfo& bootInfo();
} // namespace dcos
