// Benchmarks of the buffer pool memory agent's primitives (seed 7.7, Table 9.6).
//
// The object count is the number of pools, all created by the shell, each
// over its own 40-byte area of two 8-byte buffers (AreaBytes(8, 2)). The
// measured call acts on the newest pool, "target". BufferPool.AddObjects is
// in ConfigurationBench.cpp. The seed's GetUsageInfo is DCOS's GetStatistics.
#include "BenchSupport.hpp"

#include <dcos/BufferPoolAgent.hpp>

namespace bench {
namespace {

using dcos::bufferPoolAgent;
using dcos::BufferPoolAgent;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

constexpr size_t kBufferSize = 8;
constexpr size_t kBuffersPerPool = 2;
constexpr size_t kAreaBytes = BufferPoolAgent::AreaBytes(kBufferSize, kBuffersPerPool);

alignas(8) uint8_t areas[maximumObjectCount][kAreaBytes];
ObjectId pools[maximumObjectCount];
uint32_t poolCount = 0;
ObjectId target;
void* buffer = nullptr;
volatile uint32_t lastValue;

Result<ObjectId> createPool(uint32_t slot, const char* name)
{
    Result<ObjectId> id = bufferPoolAgent.Create(areas[slot], kAreaBytes, kBufferSize, name, dcos::Visibility::Local);
    if (id.status() == Status::TableFull) {
        const Status grown = bufferPoolAgent.AddObjects(8);
        if (grown != Status::Ok) {
            return grown;
        }
        id = bufferPoolAgent.Create(areas[slot], kAreaBytes, kBufferSize, name, dcos::Visibility::Local);
    }
    return id;
}

// Creates pools until count exist, the last one "target".
Status populate(uint32_t count)
{
    while (poolCount < count) {
        const bool last = poolCount + 1 == count;
        const Result<ObjectId> id = createPool(poolCount, last ? "target" : nullptr);
        if (!id.ok()) {
            return id.status();
        }
        pools[poolCount++] = id.value();
        if (last) {
            target = id.value();
        }
    }
    return Status::Ok;
}

void clearAll()
{
    if (buffer != nullptr) {
        (void)bufferPoolAgent.Return(target, buffer);
        buffer = nullptr;
    }
    while (poolCount > 0) {
        (void)bufferPoolAgent.Delete(pools[--poolCount]);
    }
    target = ObjectId::null();
}

// --- BufferPool.Create (variable in the seed): one more pool with N - 1;
// deleted again. The overlap check walks every pool and heap slot, and the
// layout is O(buffers) (two here).

ObjectId created;

Status populateButOne(uint32_t count) { return populate(count - 1); }

void createPool()
{
    const Result<ObjectId> id =
        bufferPoolAgent.Create(areas[poolCount], kAreaBytes, kBufferSize, nullptr, dcos::Visibility::Local);
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void deleteCreated() { (void)bufferPoolAgent.Delete(created); }

// --- BufferPool.Delete of the target (no buffer allocated); re-created unmeasured.

void deleteTarget() { check(bufferPoolAgent.Delete(target)); }

void recreateTarget()
{
    const Result<ObjectId> id = createPool(poolCount - 1, "target");
    target = id.ok() ? id.value() : ObjectId::null();
    pools[poolCount - 1] = target;
}

// --- BufferPool.Allocate and Return on the target.

void allocate()
{
    const Result<void*> allocated = bufferPoolAgent.Allocate(target);
    check(allocated.status());
    buffer = allocated.ok() ? allocated.value() : nullptr;
}

void returnBuffer()
{
    check(bufferPoolAgent.Return(target, buffer));
    buffer = nullptr;
}

void returnAllocated()
{
    (void)bufferPoolAgent.Return(target, buffer);
    buffer = nullptr;
}

void allocateAgain()
{
    const Result<void*> allocated = bufferPoolAgent.Allocate(target);
    buffer = allocated.ok() ? allocated.value() : nullptr;
}

Status populateWithBuffer(uint32_t count)
{
    const Status status = populate(count);
    if (status != Status::Ok) {
        return status;
    }
    const Result<void*> allocated = bufferPoolAgent.Allocate(target);
    buffer = allocated.ok() ? allocated.value() : nullptr;
    return allocated.status();
}

// --- BufferPool.GetUsageInfo (GetStatistics) of the target, one buffer allocated.

void getStatistics()
{
    const Result<dcos::BufferPoolStatistics> statistics = bufferPoolAgent.GetStatistics(target);
    check(statistics.status());
    lastValue = statistics.ok() ? statistics.value().freeBuffers : 0;
}

// --- BufferPool.XferOwnership of the target pool from the shell to the shell.

void transferOwnership() { check(bufferPoolAgent.XferOwnership(target, self())); }

// --- BufferPool.NameToObject (configuration): the newest pool, "target".

void nameToObject()
{
    const Result<ObjectId> id = bufferPoolAgent.NameToObject("target");
    check(id.status());
    lastValue = id.ok() ? id.value().raw() : 0;
}

} // namespace

DCOS_BENCHMARK(bufferPoolCreateBench, "BufferPool.Create", populateButOne, createPool, Cost::Variable,
               .restore = deleteCreated, .teardown = clearAll);
DCOS_BENCHMARK(bufferPoolDeleteBench, "BufferPool.Delete", populate, deleteTarget, Cost::Constant,
               .restore = recreateTarget, .teardown = clearAll);
DCOS_BENCHMARK(bufferPoolAllocateBench, "BufferPool.Allocate", populate, allocate, Cost::Constant,
               .restore = returnAllocated, .teardown = clearAll);
DCOS_BENCHMARK(bufferPoolReturnBench, "BufferPool.Return", populateWithBuffer, returnBuffer, Cost::Constant,
               .restore = allocateAgain, .teardown = clearAll);
DCOS_BENCHMARK(bufferPoolGetUsageInfoBench, "BufferPool.GetUsageInfo", populateWithBuffer, getStatistics,
               Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(bufferPoolXferOwnershipBench, "BufferPool.XferOwnership", populate, transferOwnership,
               Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(bufferPoolNameToObjectBench, "BufferPool.NameToObject", populate, nameToObject, Cost::Variable,
               .teardown = clearAll);

} // namespace bench
