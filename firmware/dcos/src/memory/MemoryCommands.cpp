// The memory agents' console commands: pools and heaps list every buffer
// pool and segmented heap with its usage (seed 7.7, 7.8, 8.3).
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/HeapManager.hpp>

#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace dcos::internal {

namespace {

void printOwner(shell::Shell& shell, ObjectId owner)
{
    if (owner.isNull()) {
        shell.print("system  ");
    } else {
        shell.print("%08lx", static_cast<unsigned long>(owner.raw()));
    }
}

// Each pool is copied under the agent's lock and printed after it, so the
// slow console never runs with interrupts disabled.
shell::CommandResult pools(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    shell.print("id        name             size   total    free     low   allocs  failed  owner\r\n");
    const size_t active = BufferPoolManager::activeCount();
    for (size_t slot = 0; slot < active; ++slot) {
        PoolInfo info;
        if (!BufferPoolManager::snapshot(slot, info)) {
            continue;
        }
        const BufferPoolStatistics& s = info.statistics;
        shell.print("%08lx  %-15s  %5lu  %6lu  %6lu  %6lu  %7lu  %6lu  ", static_cast<unsigned long>(info.id.raw()),
                    info.name[0] != '\0' ? info.name : "-", static_cast<unsigned long>(s.bufferSize),
                    static_cast<unsigned long>(s.totalBuffers), static_cast<unsigned long>(s.freeBuffers),
                    static_cast<unsigned long>(s.lowWaterMark), static_cast<unsigned long>(s.allocations),
                    static_cast<unsigned long>(s.failedAllocations));
        printOwner(shell, info.owner);
        shell.print("%s\r\n", info.corrupted ? "  CORRUPTED" : "");
    }
    shell.print("%lu of %lu pool slots used, %lu reserved\r\n",
                static_cast<unsigned long>(BufferPoolManager::usedCount()), static_cast<unsigned long>(active),
                static_cast<unsigned long>(BufferPoolManager::capacity()));
    return shell::CommandResult::Ok;
}

shell::CommandResult heaps(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    shell.print("id        name                bytes     free  largest  segs  frags  lowfree  owner\r\n");
    const size_t active = HeapManager::activeCount();
    for (size_t slot = 0; slot < active; ++slot) {
        HeapInfo info;
        if (!HeapManager::snapshot(slot, info)) {
            continue;
        }
        const HeapStatistics& s = info.statistics;
        shell.print("%08lx  %-15s  %8lu  %7lu  %7lu  %4lu  %5lu  %7lu  ", static_cast<unsigned long>(info.id.raw()),
                    info.name[0] != '\0' ? info.name : "-", static_cast<unsigned long>(s.heapBytes),
                    static_cast<unsigned long>(s.freeBytes), static_cast<unsigned long>(s.largestFreeSegment),
                    static_cast<unsigned long>(s.allocatedSegments), static_cast<unsigned long>(s.freeSegments),
                    static_cast<unsigned long>(s.lowWaterFreeBytes));
        printOwner(shell, info.owner);
        shell.print("%s\r\n", info.corrupted ? "  CORRUPTED" : "");
    }
    shell.print("%lu of %lu heap slots used, %lu reserved\r\n", static_cast<unsigned long>(HeapManager::usedCount()),
                static_cast<unsigned long>(active), static_cast<unsigned long>(HeapManager::capacity()));
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND(poolsCommand, "pools", "list the buffer pools and their usage", "pools", pools);
DCOS_SHELL_COMMAND(heapsCommand, "heaps", "list the segmented heaps and their usage", "heaps", heaps);

} // namespace dcos::internal
