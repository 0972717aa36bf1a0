// The kernel's own console commands: version, uptime and mem.
#include <dcos/Version.hpp>

#include <boot/BootInfo.hpp>
#include <bsp/Board.hpp>
#include <shell/Shell.hpp>

#include <dcos/internal/SystemTick.hpp>

namespace dcos {

const boot::BootInfo& bootInfo();

namespace {

shell::CommandResult version(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const bsp::BoardIdentity& board = bsp::identity();
    shell.print("DCOS %s (revision %s)\r\n", versionString, buildRevision());
    shell.print("board %s, processor %s, compiler GCC %d.%d.%d\r\n", board.name, board.processor, __GNUC__,
                __GNUC_MINOR__, __GNUC_PATCHLEVEL__);
    shell.print("loaded by %s\r\n", bootInfo().loaderName);
    return shell::CommandResult::Ok;
}

shell::CommandResult uptime(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const uint64_t ticks = SystemTick::count();
    const uint64_t nanoseconds = ticks * bsp::tickPeriodNanoseconds();
    const uint64_t milliseconds = nanoseconds / 1000000u;
    const uint64_t seconds = milliseconds / 1000u;
    shell.print("up %lu d %02lu:%02lu:%02lu.%03lu (%llu ticks at %lu Hz)\r\n",
                static_cast<unsigned long>(seconds / 86400u), static_cast<unsigned long>((seconds / 3600u) % 24u),
                static_cast<unsigned long>((seconds / 60u) % 60u), static_cast<unsigned long>(seconds % 60u),
                static_cast<unsigned long>(milliseconds % 1000u), static_cast<unsigned long long>(ticks),
                static_cast<unsigned long>(bsp::tickRateHz()));
    return shell::CommandResult::Ok;
}

shell::CommandResult mem(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const boot::BootInfo& info = bootInfo();
    const boot::ImageLayout image = boot::imageLayout();
    // Extended memory starts at 1 MiB, where the image is loaded.
    const uintptr_t memoryEnd = 0x100000u + uintptr_t{info.upperMemoryKib} * 1024u;
    shell.print("memory  %lu KiB conventional, %lu KiB extended\r\n", static_cast<unsigned long>(info.lowerMemoryKib),
                static_cast<unsigned long>(info.upperMemoryKib));
    shell.print("image   %08lx-%08lx %6lu KiB\r\n", static_cast<unsigned long>(image.start),
                static_cast<unsigned long>(image.end), static_cast<unsigned long>((image.end - image.start) / 1024u));
    shell.print("  bss   %08lx-%08lx %6lu KiB\r\n", static_cast<unsigned long>(image.bssStart),
                static_cast<unsigned long>(image.bssEnd),
                static_cast<unsigned long>((image.bssEnd - image.bssStart) / 1024u));
    shell.print("  stack %08lx-%08lx %6lu KiB\r\n", static_cast<unsigned long>(image.bootStackBottom),
                static_cast<unsigned long>(image.bootStackTop),
                static_cast<unsigned long>((image.bootStackTop - image.bootStackBottom) / 1024u));
    if (memoryEnd > image.end) {
        shell.print("free    %08lx-%08lx %6lu KiB\r\n", static_cast<unsigned long>(image.end),
                    static_cast<unsigned long>(memoryEnd), static_cast<unsigned long>((memoryEnd - image.end) / 1024u));
    } else {
        shell.print("free    none: the image does not fit the reported memory\r\n");
    }
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND(versionCommand, "version", "show the DCOS release, board and build", "version", version);
DCOS_SHELL_COMMAND(uptimeCommand, "uptime", "show the time since the system tick started", "uptime", uptime);
DCOS_SHELL_COMMAND(memCommand, "mem", "show the memory map", "mem", mem);

} // namespace dcos
