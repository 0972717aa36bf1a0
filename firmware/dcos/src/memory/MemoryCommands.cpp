// The memory agents' console commands: pools and heaps list every buffer
// pool and segmented heap with its usage (seed 7.7, 7.8, 8.3).
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/HeapManager.hpp>
#include <dcos/internal/IdText.hpp>

#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace dcos::internal {

namespace {

void printOwner(shell::Shell& shell, ObjectId owner)
{
    shell.print("%-10s", owner.isNull() ? "system" : internal::IdText(owner).c_str());
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
        shell.print("%-10s  %-15s  ", internal::IdText(info.id).c_str(), info.name[0] != '\0' ? info.name : "-");
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
        shell, argc, "id          name             size   total    free     low   allocs  failed  owner", "pool",
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
        shell, argc, "id          name                bytes     free  largest  segs  frags  lowfree  owner", "heap",
        [](shell::Shell& out, const HeapStatistics& s) {
            out.print("%8lu  %7lu  %7lu  %4lu  %5lu  %7lu  ", static_cast<unsigned long>(s.heapBytes),
                      static_cast<unsigned long>(s.freeBytes), static_cast<unsigned long>(s.largestFreeSegment),
                      static_cast<unsigned long>(s.allocatedSegments), static_cast<unsigned long>(s.freeSegments),
                      static_cast<unsigned long>(s.lowWaterFreeBytes));
        });
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(poolsCommand, "pools", "list the buffer pools and their usage", "pools",
                            "  id: the object id, 0x and eight hex digits in every listing and report; name: - when unnamed\r\n"
                            "  size: bytes per buffer; total, free: buffers; low: the fewest free there have been\r\n"
                            "  allocs: successful Allocate calls; failed: Allocate calls that found the pool empty\r\n"
                            "  owner: the owning task, or system; CORRUPTED: a check failed and the pool is disabled",
                            pools);
DCOS_SHELL_COMMAND_DETAILED(heapsCommand, "heaps", "list the segmented heaps and their usage", "heaps",
                            "  id: the object id, 0x and eight hex digits in every listing and report; name: - when unnamed\r\n"
                            "  bytes, free: bytes managed and free (headers included); largest: the largest request that fits now\r\n"
                            "  segs: allocated segments; frags: free segments; lowfree: the fewest free bytes there have been\r\n"
                            "  owner: the owning task, or system; CORRUPTED: a check failed and the heap is disabled",
                            heaps);

} // namespace dcos::internal
