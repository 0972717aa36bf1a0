// Turns the Multiboot v1 hand-over into a BootInfo and starts the kernel.
#include <boot/BootInfo.hpp>
#include <boot/Multiboot.hpp>

#include <arch_x86/AssemblyLinkage.hpp>
#include <arch_x86/Gdt.hpp>
#include <arch_x86/Idt.hpp>

extern "C" {
extern char __image_start[], __image_end[], __bss_start[], __bss_end[];
extern char bootStackBottom[], bootStackTop[];
using Constructor = void (*)();
extern Constructor __init_array_start[], __init_array_end[];
[[noreturn]] void dcosPanic(const char* format, ...);
}

namespace {

using MultibootInfo = boot::multiboot::Info;
constexpr uint32_t multibootBootloaderMagic = boot::multiboot::kLoaderMagic;
constexpr uint32_t multibootInfoMemory = boot::multiboot::kInfoMemory;
constexpr uint32_t multibootInfoCommandLine = boot::multiboot::kInfoCommandLine;
constexpr uint32_t multibootInfoLoaderName = boot::multiboot::kInfoLoaderName;

// The command line is copied because the loader's copy lives in memory the
// kernel does not reserve and may later reuse.
char commandLineCopy[256];

void copyString(char* destination, uint32_t capacity, const char* source)
{
    uint32_t i = 0;
    for (; i + 1 < capacity && source[i] != '\0'; ++i) {
        destination[i] = source[i];
    }
    destination[i] = '\0';
}

void runStaticConstructors()
{
    for (Constructor* constructor = __init_array_start; constructor != __init_array_end; ++constructor) {
        (*constructor)();
    }
}

} // namespace

namespace boot {

ImageLayout imageLayout()
{
    return {reinterpret_cast<uintptr_t>(__image_start), reinterpret_cast<uintptr_t>(__image_end),
            reinterpret_cast<uintptr_t>(__bss_start),   reinterpret_cast<uintptr_t>(__bss_end),
            reinterpret_cast<uintptr_t>(bootStackBottom), reinterpret_cast<uintptr_t>(bootStackTop)};
}

} // namespace boot

DCOS_ASM_LINKAGE [[noreturn]] void bootFromMultiboot(uint32_t magic, const MultibootInfo* info)
{
    // Descriptor tables first: a fault from here on is reported, not a
    // triple fault and a silent reset.
    arch_x86::Gdt::install();
    arch_x86::Idt::install();

    if (magic != multibootBootloaderMagic) {
        dcosPanic("not started by a Multiboot loader (magic 0x%08lx)", static_cast<unsigned long>(magic));
    }

    static char loaderNameCopy[48];
    boot::BootInfo bootInfo;
    if ((info->flags & multibootInfoMemory) != 0) {
        bootInfo.lowerMemoryKib = info->memLower;
        bootInfo.upperMemoryKib = info->memUpper;
    }
    if ((info->flags & multibootInfoCommandLine) != 0 && info->cmdline != 0) {
        copyString(commandLineCopy, sizeof commandLineCopy, reinterpret_cast<const char*>(info->cmdline));
        bootInfo.commandLine = commandLineCopy;
    }
    if ((info->flags & multibootInfoLoaderName) != 0 && info->bootLoaderName != 0) {
        copyString(loaderNameCopy, sizeof loaderNameCopy, reinterpret_cast<const char*>(info->bootLoaderName));
        bootInfo.loaderName = loaderNameCopy;
    } else {
        bootInfo.loaderName = "Multiboot";
    }

    runStaticConstructors();
    kernelMain(bootInfo);
}
