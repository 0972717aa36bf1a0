// Benchmarks of the segmented heap memory agent's primitives (seed 7.8, Table 9.7).
//
// The object count is the number of heaps, all created by the shell. Every
// heap but the newest covers its own 64-byte area; the newest, "target",
// covers a 4 KiB area and has a defined free-list shape for each benchmark:
//
//   Heap.Allocate, Heap.GetUsageInfo: a fresh heap, one free segment (the
//     whole heap), split by the allocation.
//   Heap.Return: [free][b][free] with b allocated: returning b merges it
//     with both neighbours (the most work a Return does).
//
// The seed's Allocate was first fit, O(free segments), and marked Variable;
// DCOS's two-level segregated fit makes Allocate and GetUsageInfo (the
// seed's name for GetStatistics) O(1), so they are Cost::Constant, and the
// "...Fragmented" benchmarks show it: there the object count is not heaps
// but free segments, one heap holding that many 24-byte free segments, every
// one too small for the request, besides the one that fits. First fit
// walked them all. Heap.AddObjects is in ConfigurationBench.cpp.
#include "BenchSupport.hpp"

#include <dcos/HeapAgent.hpp>

namespace bench {
namespace {

using dcos::heapAgent;
using dcos::HeapAgent;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

constexpr size_t kSmallAreaBytes = 64;
constexpr size_t kTargetAreaBytes = 4096;
constexpr size_t kRequest = 64; // A request of 64 bytes takes an 80-byte segment.

alignas(8) uint8_t smallAreas[maximumObjectCount][kSmallAreaBytes];
alignas(8) uint8_t targetArea[kTargetAreaBytes];
ObjectId heaps[maximumObjectCount];
uint32_t heapCount = 0;
ObjectId target;
void* segments[3] = {};
volatile uint32_t lastValue;

Result<ObjectId> createHeap(uint32_t slot, bool isTarget)
{
    void* area = isTarget ? static_cast<void*>(targetArea) : static_cast<void*>(smallAreas[slot]);
    const size_t bytes = isTarget ? kTargetAreaBytes : kSmallAreaBytes;
    const char* name = isTarget ? "target" : nullptr;
    Result<ObjectId> id = heapAgent.Create(area, bytes, name, dcos::Visibility::Local);
    if (id.status() == Status::TableFull) {
        const Status grown = heapAgent.AddObjects(8);
        if (grown != Status::Ok) {
            return grown;
        }
        id = heapAgent.Create(area, bytes, name, dcos::Visibility::Local);
    }
    return id;
}

// Creates heaps until count exist, the last one the 4 KiB "target".
Status populate(uint32_t count)
{
    while (heapCount < count) {
        const bool last = heapCount + 1 == count;
        const Result<ObjectId> id = createHeap(heapCount, last);
        if (!id.ok()) {
            return id.status();
        }
        heaps[heapCount++] = id.value();
        if (last) {
            target = id.value();
        }
    }
    return Status::Ok;
}

void returnSegments()
{
    for (void*& segment : segments) {
        if (segment != nullptr) {
            (void)heapAgent.Return(target, segment);
            segment = nullptr;
        }
    }
}

void clearAll()
{
    returnSegments();
    while (heapCount > 0) {
        (void)heapAgent.Delete(heaps[--heapCount]);
    }
    target = ObjectId::null();
}

// --- Heap.Create (variable in the seed): one more 64-byte heap with N - 1;
// deleted again. The overlap check walks every pool and heap slot.

ObjectId created;

Status populateButOne(uint32_t count) { return populate(count - 1); }

void createHeap()
{
    const Result<ObjectId> id =
        heapAgent.Create(smallAreas[heapCount], kSmallAreaBytes, nullptr, dcos::Visibility::Local);
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void deleteCreated() { (void)heapAgent.Delete(created); }

// --- Heap.Delete of the target (nothing allocated); re-created unmeasured.

void deleteTarget() { check(heapAgent.Delete(target)); }

void recreateTarget()
{
    const Result<ObjectId> id = createHeap(heapCount - 1, true);
    target = id.ok() ? id.value() : ObjectId::null();
    heaps[heapCount - 1] = target;
}

// --- Heap.Allocate on the fresh target: its one free segment fits; the
// segment is cut from its start and the rest goes to its size class.
// Returned unmeasured, which merges it back. (Named apart from the pool
// bench's allocate(), so that trace_primitive.py finds this one by name.)

void allocateSegment()
{
    const Result<void*> allocated = heapAgent.Allocate(target, kRequest);
    check(allocated.status());
    segments[0] = allocated.ok() ? allocated.value() : nullptr;
}

void returnFirst()
{
    (void)heapAgent.Return(target, segments[0]);
    segments[0] = nullptr;
}

// --- Heap.Return with a free segment on both sides. Allocation cuts from
// the start of the free segment, so three allocations give [a][b][c][free];
// returning c (merged into the free rest) and a leaves [free][b][free].
// After b's return merges all three, allocating a, b and c again and
// returning c and a rebuilds exactly that shape, with b at the same address.

void buildMergeShape()
{
    for (void*& segment : segments) {
        const Result<void*> allocated = heapAgent.Allocate(target, kRequest);
        segment = allocated.ok() ? allocated.value() : nullptr;
    }
    (void)heapAgent.Return(target, segments[2]);
    (void)heapAgent.Return(target, segments[0]);
    segments[2] = nullptr;
    segments[0] = nullptr;
}

Status populateForReturn(uint32_t count)
{
    const Status status = populate(count);
    if (status != Status::Ok) {
        return status;
    }
    buildMergeShape();
    return segments[1] != nullptr ? Status::Ok : Status::NoMemory;
}

void returnBetweenFree()
{
    check(heapAgent.Return(target, segments[1]));
    segments[1] = nullptr;
}

// --- Heap.GetUsageInfo (GetStatistics) of the fresh target: counters and
// the first segment of the highest non-empty class, checked.

void getStatistics()
{
    const Result<dcos::HeapStatistics> statistics = heapAgent.GetStatistics(target);
    check(statistics.status());
    lastValue = statistics.ok() ? statistics.value().largestFreeSegment : 0;
}

// --- Heap.XferOwnership of the target heap from the shell to the shell.

void transferOwnership() { check(heapAgent.XferOwnership(target, self())); }

// --- Heap.NameToObject (configuration): the newest heap, "target".

void nameToObject()
{
    const Result<ObjectId> id = heapAgent.NameToObject("target");
    check(id.status());
    lastValue = id.ok() ? id.value().raw() : 0;
}

// --- Heap.AllocateFragmented, Heap.GetUsageInfoFragmented: one heap that
// holds count 24-byte free segments (8 usable bytes each, too small for the
// 64-byte request) besides one large free segment.
//
// Fresh, the heap is one free segment R. 2 * count allocations of 8 bytes
// are cut from R's start: s1 first, s2 after it, ... Returning s1, s3, s5,
// ... (each before an allocated segment) leaves count small free segments,
// all in the 24-byte class, and R. First fit had to walk the small ones;
// the segregated fit goes straight to R's class. The allocation is cut from
// R's start, and returning it merges it back into R.

constexpr size_t kFragmentBytes = HeapAgent::SegmentBytes(8); // 24
constexpr size_t kLargeBytes = 512;
alignas(8) uint8_t fragmentedArea[2 * maximumObjectCount * kFragmentBytes + kLargeBytes];
ObjectId fragmentedHeap;
void* fragmentSegments[2 * maximumObjectCount];
uint32_t fragmentCount = 0; // Allocated 8-byte segments still held.

Status populateFragmented(uint32_t freeSegments)
{
    // The only heap: every other benchmark's teardown deleted its heaps.
    const Result<ObjectId> created =
        heapAgent.Create(fragmentedArea, sizeof fragmentedArea, "fragmented", dcos::Visibility::Local);
    if (!created.ok()) {
        return created.status();
    }
    fragmentedHeap = created.value();
    fragmentCount = 0;
    for (uint32_t i = 0; i < 2 * freeSegments; ++i) {
        const Result<void*> allocated = heapAgent.Allocate(fragmentedHeap, 8);
        if (!allocated.ok()) {
            return allocated.status();
        }
        fragmentSegments[fragmentCount++] = allocated.value();
    }
    // s1, s3, ... are fragmentSegments[0], [2], ...
    for (uint32_t i = 0; i < 2 * freeSegments; i += 2) {
        const Status returned = heapAgent.Return(fragmentedHeap, fragmentSegments[i]);
        if (returned != Status::Ok) {
            return returned;
        }
        fragmentSegments[i] = nullptr;
    }
    return Status::Ok;
}

void clearFragmented()
{
    if (segments[0] != nullptr) {
        (void)heapAgent.Return(fragmentedHeap, segments[0]);
        segments[0] = nullptr;
    }
    for (uint32_t i = 0; i < fragmentCount; ++i) {
        if (fragmentSegments[i] != nullptr) {
            (void)heapAgent.Return(fragmentedHeap, fragmentSegments[i]);
            fragmentSegments[i] = nullptr;
        }
    }
    fragmentCount = 0;
    (void)heapAgent.Delete(fragmentedHeap);
    fragmentedHeap = ObjectId::null();
}

void allocateFragmented()
{
    const Result<void*> allocated = heapAgent.Allocate(fragmentedHeap, kRequest);
    check(allocated.status());
    segments[0] = allocated.ok() ? allocated.value() : nullptr;
}

void returnFragmented()
{
    (void)heapAgent.Return(fragmentedHeap, segments[0]);
    segments[0] = nullptr;
}

void getFragmentedStatistics()
{
    const Result<dcos::HeapStatistics> statistics = heapAgent.GetStatistics(fragmentedHeap);
    check(statistics.status());
    lastValue = statistics.ok() ? statistics.value().freeSegments : 0;
}

} // namespace

DCOS_BENCHMARK(heapCreateBench, "Heap.Create", populateButOne, createHeap, Cost::Variable, .restore = deleteCreated,
               .teardown = clearAll);
DCOS_BENCHMARK(heapDeleteBench, "Heap.Delete", populate, deleteTarget, Cost::Constant, .restore = recreateTarget,
               .teardown = clearAll);
DCOS_BENCHMARK(heapAllocateBench, "Heap.Allocate", populate, allocateSegment, Cost::Constant, .restore = returnFirst,
               .teardown = clearAll);
DCOS_BENCHMARK(heapAllocateFragmentedBench, "Heap.AllocateFragmented", populateFragmented, allocateFragmented,
               Cost::Constant, .restore = returnFragmented, .teardown = clearFragmented);
DCOS_BENCHMARK(heapReturnBench, "Heap.Return", populateForReturn, returnBetweenFree, Cost::Constant,
               .restore = buildMergeShape, .teardown = clearAll);
DCOS_BENCHMARK(heapGetUsageInfoBench, "Heap.GetUsageInfo", populate, getStatistics, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(heapGetUsageInfoFragmentedBench, "Heap.GetUsageInfoFragmented", populateFragmented,
               getFragmentedStatistics, Cost::Constant, .teardown = clearFragmented);
DCOS_BENCHMARK(heapXferOwnershipBench, "Heap.XferOwnership", populate, transferOwnership, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(heapNameToObjectBench, "Heap.NameToObject", populate, nameToObject, Cost::Variable,
               .teardown = clearAll);

} // namespace bench
