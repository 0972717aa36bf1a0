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

// Lists every pool or heap of @p Manager: one row per object, its
// statistics printed by @p printStatistics. Each object is copied under the
// agent's lock (snapshot) and printed after it, so the slow console never
// runs with interrupts disabled.
template <class Manager, class Info, class PrintStatistics>
shell::CommandResult listAreas(shell::Shell& shell, int argc, const char* header, const char* noun,
                               PrintStatistics printStatistics)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    shell.print("%s\r\n", header);
    const size_t active = Manager::activeCount();
    for (size_t slot = 0; slot < active; ++slot) {
        Info info;
        if (!Manager::snapshot(slot, info)) {
            continue;
        }
        shell.print("%08lx  %-15s  ", static_cast<unsigned long>(info.id.raw()), info.name[0] != '\0' ? info.name : "-");
        printStatistics(shell, info.statistics);
        printOwner(shell, info.owner);
        shell.print("%s\r\n", info.corrupted ? "  CORRUPTED" : "");
    }
    shell.print("%lu of %lu %s slots used, %lu reserved\r\n", static_cast<unsigned long>(Manager::usedCount()),
                static_cast<unsigned long>(active), noun, static_cast<unsigned long>(Manager::capacity()));
    return shell::CommandResult::Ok;
}

shell::CommandResult pools(shell::Shell& shell, int argc, char**)
{
    return listAreas<BufferPoolManager, PoolInfo>(
        shell, argc, "id        name             size   total    free     low   allocs  failed  owner", "pool",
        [](shell::Shell& out, const BufferPoolStatistics& s) {
            out.print("%5lu  %6lu  %6lu  %6lu  %7lu  %6lu  ", static_cast<unsigned long>(s.bufferSize),
                      static_cast<unsigned long>(s.totalBuffers), static_cast<unsigned long>(s.freeBuffers),
                      static_cast<unsigned long>(s.lowWaterMark), static_cast<unsigned long>(s.allocations),
                      static_cast<unsigned long>(s.failedAllocations));
        });
}

shell::CommandResult heaps(shell::Shell& shell, int argc, char**)
{
    return listAreas<HeapManager, HeapInfo>(
        shell, argc, "id        name                bytes     free  largest  segs  frags  lowfree  owner", "heap",
        [](shell::Shell& out, const HeapStatistics& s) {
            out.print("%8lu  %7lu  %7lu  %4lu  %5lu  %7lu  ", static_cast<unsigned long>(s.heapBytes),
                      static_cast<unsigned long>(s.freeBytes), static_cast<unsigned long>(s.largestFreeSegment),
                      static_cast<unsigned long>(s.allocatedSegments), static_cast<unsigned long>(s.freeSegments),
                      static_cast<unsigned long>(s.lowWaterFreeBytes));
        });
}

} // namespace

DCOS_SHELL_COMMAND(poolsCommand, "pools", "list the buffer pools and their usage", "pools", pools);
DCOS_SHELL_COMMAND(heapsCommand, "heaps", "list the segmented heaps and their usage", "heaps", heaps);

} // namespace dcos::internal
