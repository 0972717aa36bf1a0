// The buffer pool and segmented heap memory agents on the target (seed 7.7,
// 7.8): every primitive with its errors, holders and ownership between
// tasks, calls from an interrupt handler, corrupted pools and heaps refusing
// service, full tables, and resource recovery when a task dies holding a
// buffer and a segment.
#include "SpareLine.hpp"
#include "KernelTestSupport.hpp"

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/HeapManager.hpp>
#include <dcos/internal/KernelContext.hpp>

namespace target_test {

namespace {

using dcos::BufferPoolAgent;
using dcos::BufferPoolStatistics;
using dcos::bufferPoolAgent;
using dcos::HeapAgent;
using dcos::heapAgent;
using dcos::HeapStatistics;
using dcos::ObjectId;
using dcos::ObjectType;
using dcos::Status;
using dcos::taskAgent;
using dcos::Visibility;
using dcos::internal::BufferPoolManager;
using dcos::internal::HeapManager;

// A node no board of the lab is given and no network table names: its ids
// come back Remote ("remote object unreachable"). The dual board's other
// node would not do, since its pools and heaps are carried between the two.
constexpr uint16_t kUnknownNode = 0x7001;

// An interrupt line no device uses on the emulated board; the test raises
// its vector (0x20 + line) by software.

// The messages below state the heap's figures: a 16-byte header, so that
// one byte takes 24.
static_assert(HeapAgent::kHeaderBytes == 16 && HeapAgent::kMinimumSegment == 8,
              "the heap's layout changed: update the figures in the checks' messages");

// The smallest pool (one 4-byte buffer) and the smallest heap (one segment).
constexpr size_t kSmallPoolBytes = BufferPoolAgent::AreaBytes(4, 1);
constexpr size_t kSmallHeapBytes = HeapAgent::SegmentBytes(1);

// Areas the application owns, as the agents' documentation describes. A
// small area's row holds one 8-byte buffer, or the smallest pool or heap; it
// is a multiple of 8 bytes, so every row starts aligned.
alignas(8) uint8_t poolArea[BufferPoolAgent::AreaBytes(32, 8)];
alignas(8) uint8_t otherPoolArea[BufferPoolAgent::AreaBytes(16, 4)];
alignas(8) uint8_t smallAreas[24][BufferPoolAgent::AreaBytes(8, 1)];
alignas(8) uint8_t heapArea[4096];
alignas(8) uint8_t otherHeapArea[1024];
alignas(8) uint8_t smallHeapAreas[24][kSmallHeapBytes];
static_assert(sizeof smallAreas[0] % 8 == 0 && sizeof smallAreas[0] >= kSmallPoolBytes
              && sizeof smallHeapAreas[0] % 8 == 0);

bool isInside(const void* pointer, const void* area, size_t bytes)
{
    const uint8_t* p = static_cast<const uint8_t*>(pointer);
    const uint8_t* begin = static_cast<const uint8_t*>(area);
    return p >= begin && p < begin + bytes;
}

BufferPoolStatistics poolStatistics(ObjectId pool) { return bufferPoolAgent.GetStatistics(pool).value(); }

HeapStatistics heapStatistics(ObjectId heap) { return heapAgent.GetStatistics(heap).value(); }

// Runs a console command from a test, so its output lands in the transcript.
void runCommand(shell::Shell& shell, const char* command)
{
    char line[16];
    size_t i = 0;
    for (; command[i] != '\0' && i + 1 < sizeof line; ++i) {
        line[i] = command[i];
    }
    line[i] = '\0';
    shell.execute(line);
}

// What a plain (not super-user) task sees when it uses objects the test task owns.
struct UserTaskResults {
    ObjectId object;      // The pool or heap to use.
    void* theirs;         // A buffer or segment the test task holds.
    Status returnTheirs;  // Returning it.
    Status deleteObject;  // Deleting the object.
    Status takeObject;    // XferOwnership of the object to itself.
    Status addObjects;    // AddObjects(8).
    Status allocate;      // Allocating its own buffer or segment.
    Status handOver;      // XferOwnership of that buffer or segment to the test task.
    void* mine;           // That buffer or segment.
};

UserTaskResults userResults;

void poolUserEntry(uintptr_t)
{
    UserTaskResults& r = userResults;
    r.returnTheirs = bufferPoolAgent.Return(r.object, r.theirs);
    r.deleteObject = bufferPoolAgent.Delete(r.object);
    r.takeObject = bufferPoolAgent.XferOwnership(r.object, taskAgent.IdOfSelf());
    r.addObjects = bufferPoolAgent.AddObjects(8);
    const dcos::Result<void*> mine = bufferPoolAgent.Allocate(r.object);
    r.allocate = mine.status();
    r.mine = mine.ok() ? mine.value() : nullptr;
    r.handOver = bufferPoolAgent.XferOwnership(r.object, r.mine, testTask());
    finished();
}

void heapUserEntry(uintptr_t)
{
    UserTaskResults& r = userResults;
    r.returnTheirs = heapAgent.Return(r.object, r.theirs);
    r.deleteObject = heapAgent.Delete(r.object);
    r.takeObject = heapAgent.XferOwnership(r.object, taskAgent.IdOfSelf());
    r.addObjects = heapAgent.AddObjects(8);
    const dcos::Result<void*> mine = heapAgent.Allocate(r.object, 50);
    r.allocate = mine.status();
    r.mine = mine.ok() ? mine.value() : nullptr;
    r.handOver = heapAgent.XferOwnership(r.object, r.mine, testTask());
    finished();
}

bool checkUserResults(shell::Shell& shell, const char* agent)
{
    const UserTaskResults& r = userResults;
    shell.print("%s seen by a user task: return another's %s, delete %s, take %s, add %s, allocate %s, hand over %s\r\n",
                agent, dcos::statusName(r.returnTheirs), dcos::statusName(r.deleteObject),
                dcos::statusName(r.takeObject), dcos::statusName(r.addObjects), dcos::statusName(r.allocate),
                dcos::statusName(r.handOver));
    bool ok = checkStatus(shell, r.returnTheirs, Status::NotOwner, "returning what another task holds");
    ok = checkStatus(shell, r.deleteObject, Status::NotOwner, "Delete by a task that does not own it") && ok;
    ok = checkStatus(shell, r.takeObject, Status::NotOwner, "XferOwnership by a task that does not own it") && ok;
    ok = checkStatus(shell, r.addObjects, Status::NotPermitted, "AddObjects by a user task") && ok;
    ok = checkStatus(shell, r.allocate, Status::Ok, "any task may allocate") && ok;
    ok = checkStatus(shell, r.handOver, Status::Ok, "hand over to the test task") && ok;
    return ok;
}

bool pools(shell::Shell& shell)
{
    const uint16_t node = dcos::internal::localNode();
    const dcos::Result<ObjectId> created =
        bufferPoolAgent.Create(poolArea, sizeof poolArea, 32, "test-pool", Visibility::Local);
    if (!checkStatus(shell, created.status(), Status::Ok, "Create")) {
        return false;
    }
    const ObjectId pool = created.value();
    BufferPoolStatistics statistics = poolStatistics(pool);
    shell.print("pool %08lx: %lu buffers of %lu bytes in %u bytes\r\n", static_cast<unsigned long>(pool.raw()),
                static_cast<unsigned long>(statistics.totalBuffers), static_cast<unsigned long>(statistics.bufferSize),
                static_cast<unsigned>(sizeof poolArea));
    bool ok = check(shell, statistics.totalBuffers == 8 && statistics.freeBuffers == 8 && statistics.bufferSize == 32,
                    "AreaBytes(32, 8) holds eight 32-byte buffers");

    // Create's errors.
    ok = checkStatus(shell,
                     bufferPoolAgent.Create(smallAreas[0], kSmallPoolBytes, 3, nullptr, Visibility::Local).status(),
                     Status::InvalidArgument, "buffers of 3 bytes") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Create(nullptr, 64, 8, nullptr, Visibility::Local).status(),
                     Status::InvalidArgument, "no area") && ok;
    ok = checkStatus(shell,
                     bufferPoolAgent.Create(smallAreas[0], sizeof smallAreas[0] - 1, 8, nullptr, Visibility::Local)
                         .status(),
                     Status::InvalidArgument, "an area too small for one buffer") && ok;
    ok = checkStatus(shell,
                     bufferPoolAgent.Create(poolArea + 40, kSmallPoolBytes, 4, nullptr, Visibility::Local).status(),
                     Status::AlreadyExists, "an area inside another pool's") && ok;
    ok = checkStatus(shell,
                     bufferPoolAgent.Create(smallAreas[0], kSmallPoolBytes, 4, "sixteen-letters!", Visibility::Local)
                         .status(),
                     Status::InvalidArgument, "a name of 16 characters") && ok;

    // Allocate until empty: distinct buffers inside the area, aligned.
    void* buffers[8] = {};
    bool distinct = true;
    for (size_t i = 0; i < 8; ++i) {
        const dcos::Result<void*> buffer = bufferPoolAgent.Allocate(pool);
        ok = checkStatus(shell, buffer.status(), Status::Ok, "Allocate") && ok;
        buffers[i] = buffer.ok() ? buffer.value() : nullptr;
        distinct = distinct && isInside(buffers[i], poolArea, sizeof poolArea)
                   && reinterpret_cast<uintptr_t>(buffers[i]) % 8 == 0;
        for (size_t j = 0; j < i; ++j) {
            distinct = distinct && buffers[j] != buffers[i];
        }
        for (size_t byte = 0; byte < 32 && buffers[i] != nullptr; ++byte) {
            static_cast<uint8_t*>(buffers[i])[byte] = static_cast<uint8_t>(i);
        }
    }
    ok = check(shell, distinct, "eight distinct aligned buffers inside the area") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(pool).status(), Status::NoMemory, "Allocate from an empty pool") && ok;
    statistics = poolStatistics(pool);
    ok = check(shell, statistics.freeBuffers == 0 && statistics.lowWaterMark == 0 && statistics.allocations == 8
                          && statistics.failedAllocations == 1,
               "statistics: none free, low-water 0, 8 allocations, 1 failed") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Return(pool, buffers[3]), Status::Ok, "Return") && ok;
    const dcos::Result<void*> again = bufferPoolAgent.Allocate(pool);
    ok = check(shell, again.ok() && again.value() == buffers[3], "the returned buffer is allocated again") && ok;
    bool intact = true;
    for (size_t i = 0; i < 8; ++i) {
        for (size_t byte = 0; byte < 32 && i != 3; ++byte) {
            intact = intact && static_cast<uint8_t*>(buffers[i])[byte] == i;
        }
    }
    ok = check(shell, intact, "the pool never wrote into an allocated buffer") && ok;

    // Names.
    const dcos::Result<ObjectId> named = bufferPoolAgent.NameToObject("test-pool");
    ok = check(shell, named.ok() && named.value() == pool, "NameToObject") && ok;
    ok = checkStatus(shell, bufferPoolAgent.NameToObject("no-such-pool").status(), Status::NotFound,
                     "NameToObject of an unknown name") && ok;

    // A pointer outside the pool is refused and the pool stays in service.
    uint32_t notABuffer[8];
    ok = checkStatus(shell, bufferPoolAgent.Return(pool, notABuffer), Status::InvalidArgument, "a foreign pointer") && ok;
    ok = checkStatus(shell, bufferPoolAgent.GetStatistics(pool).status(), Status::Ok, "the pool is still in service") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(pool), Status::Busy, "Delete while buffers are out") && ok;

    // Holders and ownership between tasks.
    ok = checkStatus(shell, bufferPoolAgent.Return(pool, buffers[7]), Status::Ok, "Return before the user runs") && ok;
    userResults = UserTaskResults{};
    userResults.object = pool;
    userResults.theirs = buffers[0];
    spawn("pool-user", 10, poolUserEntry);
    ok = check(shell, waitForDone(shell, 1), "the user task finished") && ok;
    ok = checkUserResults(shell, "pool") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Return(pool, userResults.mine), Status::Ok, "return a handed-over buffer") && ok;
    ok = checkStatus(shell, bufferPoolAgent.XferOwnership(pool, buffers[1], ObjectId::null()), Status::Ok,
                     "hand a buffer to the system") && ok;
    ok = checkStatus(shell, bufferPoolAgent.XferOwnership(pool, buffers[1], taskAgent.IdOfSelf()), Status::Ok,
                     "any task may take a system buffer") && ok;
    ok = checkStatus(shell, bufferPoolAgent.XferOwnership(pool, buffers[2], ObjectId(node, ObjectType::Task, 0x0F0)),
                     Status::InvalidId, "hand a buffer to no task") && ok;
    ok = checkStatus(shell, bufferPoolAgent.XferOwnership(pool, taskAgent.NameToObject("idle").value()), Status::Ok,
                     "XferOwnership of the pool") && ok;
    ok = checkStatus(shell, bufferPoolAgent.XferOwnership(pool, taskAgent.IdOfSelf()), Status::Ok,
                     "a super user takes it back") && ok;

    // Id errors.
    const ObjectId forged(node, ObjectType::BufferPool, static_cast<uint16_t>((pool.index() + 3) & 7));
    ok = checkStatus(shell, bufferPoolAgent.Allocate(ObjectId::null()).status(), Status::InvalidId, "the null id") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(forged).status(), Status::InvalidId, "a free slot") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(ObjectId(node, ObjectType::BufferPool, 0x03F)).status(),
                     Status::InvalidId, "a slot beyond the active ones") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(taskAgent.IdOfSelf()).status(), Status::WrongType, "a task id") && ok;
    ok = checkStatus(shell,
                     bufferPoolAgent.Allocate(ObjectId(kUnknownNode, ObjectType::BufferPool, pool.index())).status(),
                     Status::Remote, "a pool of a node the network tables do not know") && ok;

    // Delete once every buffer is back; the id turns stale.
    for (size_t i = 0; i < 7; ++i) {
        ok = checkStatus(shell, bufferPoolAgent.Return(pool, buffers[i]), Status::Ok, "Return every buffer") && ok;
    }
    statistics = poolStatistics(pool);
    ok = check(shell, statistics.freeBuffers == 8 && statistics.returns == 10, "all eight free, ten returns") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(pool), Status::Ok, "Delete") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(pool).status(), Status::StaleId, "Allocate after Delete") && ok;
    ok = checkStatus(shell, bufferPoolAgent.GetStatistics(pool).status(), Status::StaleId, "GetStatistics after Delete") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(pool), Status::StaleId, "Delete twice") && ok;
    // The area is the application's again: a new pool may use it.
    const dcos::Result<ObjectId> reused = bufferPoolAgent.Create(poolArea, sizeof poolArea, 64, nullptr, Visibility::Local);
    ok = check(shell, reused.ok() && poolStatistics(reused.value()).totalBuffers == 4, "the area holds a new pool") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(reused.value()), Status::Ok, "Delete the new pool") && ok;
    return ok;
}

DCOS_TARGET_TEST(poolsTest, "pools", "buffer pool primitives, holders and their errors", pools);

bool heaps(shell::Shell& shell)
{
    const uint16_t node = dcos::internal::localNode();
    const dcos::Result<ObjectId> created = heapAgent.Create(heapArea, sizeof heapArea, "test-heap", Visibility::Local);
    if (!checkStatus(shell, created.status(), Status::Ok, "Create")) {
        return false;
    }
    const ObjectId heap = created.value();
    // The largest request a heap of one free segment grants: all of it but a header.
    constexpr size_t kLargest = sizeof heapArea - HeapAgent::kHeaderBytes;
    HeapStatistics statistics = heapStatistics(heap);
    bool ok = check(shell, statistics.heapBytes == 4096 && statistics.freeBytes == 4096 && statistics.freeSegments == 1
                               && statistics.largestFreeSegment == kLargest,
                    "a fresh heap is one free segment of 4096 bytes");

    // Create's errors.
    ok = checkStatus(shell, heapAgent.Create(nullptr, 64, nullptr, Visibility::Local).status(), Status::InvalidArgument,
                     "no area") && ok;
    ok = checkStatus(shell, heapAgent.Create(smallHeapAreas[0], kSmallHeapBytes - 1, nullptr, Visibility::Local).status(),
                     Status::InvalidArgument, "an area below one segment") && ok;
    ok = checkStatus(shell, heapAgent.Create(heapArea + 1000, 64, nullptr, Visibility::Local).status(),
                     Status::AlreadyExists, "an area inside another heap's") && ok;
    const ObjectId pool = bufferPoolAgent.Create(otherPoolArea, sizeof otherPoolArea, 16, nullptr, Visibility::Local).value();
    ok = checkStatus(shell, heapAgent.Create(otherPoolArea, sizeof otherPoolArea, nullptr, Visibility::Local).status(),
                     Status::AlreadyExists, "an area of a pool") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Create(heapArea, 64, 8, nullptr, Visibility::Local).status(),
                     Status::AlreadyExists, "a pool in a heap's area") && ok;
    (void)bufferPoolAgent.Delete(pool);

    // Sizes, alignment, the 16-byte header and minimum.
    ok = checkStatus(shell, heapAgent.Allocate(heap, 0).status(), Status::InvalidArgument, "Allocate(0)") && ok;
    ok = checkStatus(shell, heapAgent.Allocate(heap, kLargest + 1).status(), Status::NoMemory, "more than the heap") && ok;
    void* a = heapAgent.Allocate(heap, 1).value();
    ok = check(shell, isInside(a, heapArea, sizeof heapArea) && reinterpret_cast<uintptr_t>(a) % 8 == 0,
               "a segment is 8-byte aligned inside the area") && ok;
    ok = check(shell, heapStatistics(heap).usedBytes == HeapAgent::kHeaderBytes + 8,
               "one byte takes 24: a 16-byte header and the 8-byte minimum") && ok;
    // c's segment, 192 bytes and a header (208), is the first size of its
    // class: a request of the same size takes it back below.
    void* b = heapAgent.Allocate(heap, 100).value();
    void* c = heapAgent.Allocate(heap, 192).value();
    void* d = heapAgent.Allocate(heap, 8).value();
    ok = check(shell, b != nullptr && c != nullptr && d != nullptr, "three more segments") && ok;
    constexpr size_t kUsedByFour = (8 + HeapAgent::kHeaderBytes) + (104 + HeapAgent::kHeaderBytes)
                                   + (192 + HeapAgent::kHeaderBytes) + (8 + HeapAgent::kHeaderBytes);
    ok = check(shell, heapStatistics(heap).usedBytes == kUsedByFour,
               "each costs its size rounded up to 8, plus the 16-byte header") && ok;
    for (size_t i = 0; i < 100; ++i) {
        static_cast<uint8_t*>(b)[i] = 0xB0;
    }

    // Reuse of a free segment of the right size class, and merging on both sides.
    ok = checkStatus(shell, heapAgent.Return(heap, a), Status::Ok, "Return a") && ok;
    ok = checkStatus(shell, heapAgent.Return(heap, c), Status::Ok, "Return c") && ok;
    statistics = heapStatistics(heap);
    shell.print("after two returns: %lu free segments, largest %lu bytes\r\n",
                static_cast<unsigned long>(statistics.freeSegments),
                static_cast<unsigned long>(statistics.largestFreeSegment));
    ok = check(shell, statistics.freeSegments == 3, "a and c are separate free segments") && ok;
    const dcos::Result<void*> fits = heapAgent.Allocate(heap, 192);
    ok = check(shell, fits.ok() && fits.value() == c, "the size class of c's segment gives it back for the same size") && ok;
    ok = checkStatus(shell, heapAgent.Return(heap, c), Status::Ok, "Return c again") && ok;
    ok = checkStatus(shell, heapAgent.Return(heap, b), Status::Ok, "Return b, between two free segments") && ok;
    ok = check(shell, heapStatistics(heap).freeSegments == 2, "b merged with both neighbours") && ok;
    ok = checkStatus(shell, heapAgent.Return(heap, d), Status::Ok, "Return d") && ok;
    statistics = heapStatistics(heap);
    ok = check(shell,
               statistics.freeSegments == 1 && statistics.largestFreeSegment == kLargest && statistics.usedBytes == 0,
               "everything merged back into one segment") && ok;
    ok = check(shell, statistics.allocations == 5 && statistics.failedAllocations == 1 && statistics.returns == 5,
               "statistics count 5 allocations, 1 failure, 5 returns") && ok;
    ok = check(shell, statistics.lowWaterFreeBytes == 4096 - kUsedByFour, "low-water mark of free bytes") && ok;

    // Names, holders and ownership between tasks.
    const dcos::Result<ObjectId> named = heapAgent.NameToObject("test-heap");
    ok = check(shell, named.ok() && named.value() == heap, "NameToObject") && ok;
    void* held = heapAgent.Allocate(heap, 64).value();
    userResults = UserTaskResults{};
    userResults.object = heap;
    userResults.theirs = held;
    spawn("heap-user", 10, heapUserEntry);
    ok = check(shell, waitForDone(shell, 1), "the user task finished") && ok;
    ok = checkUserResults(shell, "heap") && ok;
    ok = checkStatus(shell, heapAgent.Return(heap, userResults.mine), Status::Ok, "return a handed-over segment") && ok;
    ok = checkStatus(shell, heapAgent.XferOwnership(heap, taskAgent.NameToObject("idle").value()), Status::Ok,
                     "XferOwnership of the heap") && ok;
    ok = checkStatus(shell, heapAgent.XferOwnership(heap, taskAgent.IdOfSelf()), Status::Ok,
                     "a super user takes it back") && ok;
    ok = checkStatus(shell, heapAgent.XferOwnership(heap, held, ObjectId(node, ObjectType::Task, 0x0F0)),
                     Status::InvalidId, "hand a segment to no task") && ok;
    uint64_t notASegment[4];
    ok = checkStatus(shell, heapAgent.Return(heap, notASegment), Status::InvalidArgument, "a foreign pointer") && ok;
    ok = checkStatus(shell, heapAgent.Delete(heap), Status::Busy, "Delete while a segment is out") && ok;

    // Id errors.
    ok = checkStatus(shell, heapAgent.Allocate(ObjectId::null(), 8).status(), Status::InvalidId, "the null id") && ok;
    ok = checkStatus(shell, heapAgent.Allocate(ObjectId(node, ObjectType::Heap, 0x03F), 8).status(), Status::InvalidId,
                     "a slot beyond the active ones") && ok;
    ok = checkStatus(shell, heapAgent.Allocate(pool, 8).status(), Status::WrongType, "a pool id") && ok;
    ok = checkStatus(shell,
                     heapAgent.Allocate(ObjectId(kUnknownNode, ObjectType::Heap, heap.index()), 8).status(),
                     Status::Remote, "a heap of a node the network tables do not know") && ok;

    ok = checkStatus(shell, heapAgent.Return(heap, held), Status::Ok, "Return the last segment") && ok;
    ok = checkStatus(shell, heapAgent.Delete(heap), Status::Ok, "Delete") && ok;
    ok = checkStatus(shell, heapAgent.Allocate(heap, 8).status(), Status::StaleId, "Allocate after Delete") && ok;
    ok = checkStatus(shell, heapAgent.Return(heap, held), Status::StaleId, "Return after Delete") && ok;
    return ok;
}

DCOS_TARGET_TEST(heapsTest, "heaps", "segmented heap primitives, segregated fit, merging, holders and errors", heaps);

bool tables(shell::Shell& shell)
{
    bool ok = true;
    ObjectId created[24];
    size_t count = 0;
    Status last = Status::Ok;
    const size_t expected = BufferPoolManager::activeCount() - BufferPoolManager::usedCount();
    for (; count < 24; ++count) {
        const dcos::Result<ObjectId> id =
            bufferPoolAgent.Create(smallAreas[count], kSmallPoolBytes, 4, nullptr, Visibility::Local);
        if (!id.ok()) {
            last = id.status();
            break;
        }
        created[count] = id.value();
    }
    shell.print("created %u pools, then: %s\r\n", static_cast<unsigned>(count), dcos::statusName(last));
    ok = checkStatus(shell, last, Status::TableFull, "a full pool table") && ok;
    ok = check(shell, count == expected, "as many pools as active free slots") && ok;
    ok = checkStatus(shell, bufferPoolAgent.AddObjects(5), Status::InvalidArgument, "AddObjects(5)") && ok;
    ok = checkStatus(shell, bufferPoolAgent.AddObjects(BufferPoolManager::capacity()), Status::TableFull,
                     "AddObjects beyond the capacity") && ok;
    ok = checkStatus(shell, bufferPoolAgent.AddObjects(8), Status::Ok, "AddObjects(8)") && ok;
    const dcos::Result<ObjectId> more =
        bufferPoolAgent.Create(smallAreas[count], kSmallPoolBytes, 4, nullptr, Visibility::Local);
    ok = check(shell, more.ok(), "AddObjects made room") && ok;
    for (size_t i = 0; i < count; ++i) {
        ok = checkStatus(shell, bufferPoolAgent.Delete(created[i]), Status::Ok, "Delete a pool") && ok;
    }
    (void)bufferPoolAgent.Delete(more.value());

    count = 0;
    last = Status::Ok;
    const size_t expectedHeaps = HeapManager::activeCount() - HeapManager::usedCount();
    for (; count < 24; ++count) {
        const dcos::Result<ObjectId> id =
            heapAgent.Create(smallHeapAreas[count], kSmallHeapBytes, nullptr, Visibility::Local);
        if (!id.ok()) {
            last = id.status();
            break;
        }
        created[count] = id.value();
    }
    shell.print("created %u heaps, then: %s\r\n", static_cast<unsigned>(count), dcos::statusName(last));
    ok = checkStatus(shell, last, Status::TableFull, "a full heap table") && ok;
    ok = check(shell, count == expectedHeaps, "as many heaps as active free slots") && ok;
    ok = checkStatus(shell, heapAgent.AddObjects(0), Status::InvalidArgument, "AddObjects(0)") && ok;
    ok = checkStatus(shell, heapAgent.AddObjects(8), Status::Ok, "AddObjects(8)") && ok;
    const dcos::Result<ObjectId> moreHeap =
        heapAgent.Create(smallHeapAreas[count], kSmallHeapBytes, nullptr, Visibility::Local);
    ok = check(shell, moreHeap.ok(), "AddObjects made room") && ok;
    for (size_t i = 0; i < count; ++i) {
        ok = checkStatus(shell, heapAgent.Delete(created[i]), Status::Ok, "Delete a heap") && ok;
    }
    (void)heapAgent.Delete(moreHeap.value());
    ok = check(shell, BufferPoolManager::usedCount() == 0 && HeapManager::usedCount() == 0, "every table is empty again")
         && ok;
    return ok;
}

DCOS_TARGET_TEST(memoryTablesTest, "memtables", "full pool and heap tables give TableFull until AddObjects", tables);

bool poolCorruption(shell::Shell& shell)
{
    // A buffer returned twice.
    const ObjectId pool = bufferPoolAgent.Create(poolArea, sizeof poolArea, 32, "bad-pool", Visibility::Local).value();
    void* first = bufferPoolAgent.Allocate(pool).value();
    void* second = bufferPoolAgent.Allocate(pool).value();
    bool ok = checkStatus(shell, bufferPoolAgent.Return(pool, second), Status::Ok, "Return");
    ok = checkStatus(shell, bufferPoolAgent.Return(pool, second), Status::Corrupted, "the same buffer again") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(pool).status(), Status::Corrupted, "Allocate after it") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Return(pool, first), Status::Corrupted, "Return after it") && ok;
    ok = checkStatus(shell, bufferPoolAgent.GetStatistics(pool).status(), Status::Corrupted, "GetStatistics after it")
         && ok;
    ok = checkStatus(shell, bufferPoolAgent.XferOwnership(pool, first, ObjectId::null()), Status::Corrupted,
                     "XferOwnership of a buffer after it") && ok;
    runCommand(shell, "pools");
    ok = checkStatus(shell, bufferPoolAgent.Delete(pool), Status::Ok, "Delete, with a buffer still out") && ok;

    // A task writes into a buffer after returning it: the pool keeps nothing
    // there, so only the task's own data suffers.
    const ObjectId second_pool =
        bufferPoolAgent.Create(otherPoolArea, sizeof otherPoolArea, 16, nullptr, Visibility::Local).value();
    void* buffer = bufferPoolAgent.Allocate(second_pool).value();
    ok = checkStatus(shell, bufferPoolAgent.Return(second_pool, buffer), Status::Ok, "Return") && ok;
    static_cast<volatile uint32_t*>(buffer)[0] = 0x12345678;
    void* again = bufferPoolAgent.Allocate(second_pool).value();
    ok = check(shell, again == buffer, "a write after Return leaves the free list intact") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Return(second_pool, again), Status::Ok, "Return it again") && ok;
    // A stray write into the state table at the area's start (buffer 0's
    // state word, the head of the free list) overwrites the free list.
    reinterpret_cast<volatile uint32_t*>(otherPoolArea)[0] = 0x12345678;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(second_pool).status(), Status::Corrupted,
                     "Allocate over an overwritten free list") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(second_pool).status(), Status::Corrupted,
                     "and every later call") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(second_pool), Status::Ok, "Delete") && ok;

    // A pointer into the pool that is not a buffer's start.
    const ObjectId third = bufferPoolAgent.Create(poolArea, sizeof poolArea, 32, nullptr, Visibility::Local).value();
    uint8_t* inside = static_cast<uint8_t*>(bufferPoolAgent.Allocate(third).value()) + 4;
    ok = checkStatus(shell, bufferPoolAgent.Return(third, inside), Status::Corrupted, "a pointer inside a buffer") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(third), Status::Ok, "Delete") && ok;
    return ok;
}

DCOS_TARGET_TEST(poolCorruptionTest, "poolcorrupt", "a corrupted pool is reported and refuses every call until deleted",
                 poolCorruption);

bool heapCorruption(shell::Shell& shell)
{
    // A segment returned twice.
    const ObjectId heap = heapAgent.Create(heapArea, sizeof heapArea, "bad-heap", Visibility::Local).value();
    void* a = heapAgent.Allocate(heap, 24).value();
    void* b = heapAgent.Allocate(heap, 24).value();
    bool ok = checkStatus(shell, heapAgent.Return(heap, b), Status::Ok, "Return");
    ok = checkStatus(shell, heapAgent.Return(heap, b), Status::Corrupted, "the same segment again") && ok;
    ok = checkStatus(shell, heapAgent.Allocate(heap, 8).status(), Status::Corrupted, "Allocate after it") && ok;
    ok = checkStatus(shell, heapAgent.Return(heap, a), Status::Corrupted, "Return after it") && ok;
    ok = checkStatus(shell, heapAgent.GetStatistics(heap).status(), Status::Corrupted, "GetStatistics after it") && ok;
    runCommand(shell, "heaps");
    ok = checkStatus(shell, heapAgent.Delete(heap), Status::Ok, "Delete, with a segment still out") && ok;

    // A task writes past the end of its segment into the next one's header.
    const ObjectId second = heapAgent.Create(otherHeapArea, sizeof otherHeapArea, nullptr, Visibility::Local).value();
    uint8_t* lower = static_cast<uint8_t*>(heapAgent.Allocate(second, 24).value());
    uint8_t* upper = static_cast<uint8_t*>(heapAgent.Allocate(second, 24).value());
    ok = check(shell, lower + HeapAgent::SegmentBytes(24) == upper, "segments are cut from the start of the free segment")
         && ok;
    // Its 24 bytes, then the next segment's whole header (size and flags,
    // check and holder, the held-list links).
    for (size_t i = 0; i < 24 + HeapAgent::kHeaderBytes; ++i) {
        static_cast<volatile uint8_t*>(lower)[i] = 0x55;
    }
    ok = checkStatus(shell, heapAgent.Return(second, upper), Status::Corrupted, "Return of the overwritten segment") && ok;
    ok = checkStatus(shell, heapAgent.Delete(second), Status::Ok, "Delete") && ok;

    // A free segment's links overwritten after its return.
    const ObjectId third = heapAgent.Create(otherHeapArea, sizeof otherHeapArea, nullptr, Visibility::Local).value();
    void* kept = heapAgent.Allocate(third, 40).value();
    void* freed = heapAgent.Allocate(third, 40).value();
    (void)heapAgent.Allocate(third, 40);
    ok = checkStatus(shell, heapAgent.Return(third, freed), Status::Ok, "Return") && ok;
    // A free segment keeps its links at its start + 4 (previous) and + 8
    // (next); its data began a header after its start.
    uint8_t* const freedStart = static_cast<uint8_t*>(freed) - HeapAgent::kHeaderBytes;
    // Its next link, now naming offset 16: the middle of kept's segment.
    reinterpret_cast<volatile uint32_t*>(freedStart + 8)[0] = 0x00000010;
    // A request of the same size takes the first segment of that size class: the freed one.
    ok = checkStatus(shell, heapAgent.Allocate(third, 40).status(), Status::Corrupted,
                     "Allocate over an overwritten link") && ok;
    ok = checkStatus(shell, heapAgent.Return(third, kept), Status::Corrupted, "and every later call") && ok;
    ok = checkStatus(shell, heapAgent.Delete(third), Status::Ok, "Delete") && ok;
    return ok;
}

DCOS_TARGET_TEST(heapCorruptionTest, "heapcorrupt", "a corrupted heap is reported and refuses every call until deleted",
                 heapCorruption);

// What the interrupt handler got.
struct IsrResults {
    ObjectId pool;
    ObjectId heap;
    void* taskBuffer;
    Status allocateBuffer;
    Status allocateSegment;
    Status returnTaskBuffer;
    Status create;
    Status nameToObject;
    Status statistics;
    void* buffer;
    void* segment;
};

IsrResults isrResults;
volatile bool isrRan = false;

void memoryIsr(void*)
{
    IsrResults& r = isrResults;
    const dcos::Result<void*> buffer = bufferPoolAgent.Allocate(r.pool);
    r.allocateBuffer = buffer.status();
    r.buffer = buffer.ok() ? buffer.value() : nullptr;
    const dcos::Result<void*> segment = heapAgent.Allocate(r.heap, 40);
    r.allocateSegment = segment.status();
    r.segment = segment.ok() ? segment.value() : nullptr;
    r.returnTaskBuffer = bufferPoolAgent.Return(r.pool, r.taskBuffer);
    r.create = bufferPoolAgent.Create(smallAreas[0], kSmallPoolBytes, 4, nullptr, Visibility::Local).status();
    r.nameToObject = heapAgent.NameToObject("isr-heap").status();
    r.statistics = bufferPoolAgent.GetStatistics(r.pool).status();
    isrRan = true;
}

void returnSystemEntry(uintptr_t)
{
    isrResults.returnTaskBuffer = bufferPoolAgent.Return(isrResults.pool, isrResults.buffer);
    isrResults.allocateSegment = heapAgent.Return(isrResults.heap, isrResults.segment);
    finished();
}

bool memoryInInterrupts(shell::Shell& shell)
{
    isrResults = IsrResults{};
    isrResults.pool = bufferPoolAgent.Create(poolArea, sizeof poolArea, 32, nullptr, Visibility::Local).value();
    isrResults.heap = heapAgent.Create(heapArea, sizeof heapArea, "isr-heap", Visibility::Local).value();
    isrResults.taskBuffer = bufferPoolAgent.Allocate(isrResults.pool).value();
    isrRan = false;
    bool ok = checkStatus(shell, dcos::systemAgent.InstallISR(target_test::spareLine(), memoryIsr, nullptr), Status::Ok, "InstallISR");
    target_test::raiseSpareLine();
    ok = check(shell, isrRan, "the routine ran") && ok;
    ok = checkStatus(shell, isrResults.allocateBuffer, Status::Ok, "Allocate a buffer in an ISR") && ok;
    ok = checkStatus(shell, isrResults.allocateSegment, Status::Ok, "Allocate a segment in an ISR") && ok;
    ok = checkStatus(shell, isrResults.returnTaskBuffer, Status::NotOwner, "an ISR returns only system buffers") && ok;
    ok = checkStatus(shell, isrResults.create, Status::InInterrupt, "Create in an ISR") && ok;
    ok = checkStatus(shell, isrResults.nameToObject, Status::InInterrupt, "NameToObject in an ISR") && ok;
    ok = checkStatus(shell, isrResults.statistics, Status::Ok, "GetStatistics in an ISR") && ok;
    ok = checkStatus(shell, dcos::systemAgent.RemoveISR(target_test::spareLine()), Status::Ok, "RemoveISR") && ok;
    // What an ISR allocates is held by the system: any task may return it.
    spawn("returner", 10, returnSystemEntry);
    ok = check(shell, waitForDone(shell, 1), "the returning task finished") && ok;
    ok = checkStatus(shell, isrResults.returnTaskBuffer, Status::Ok, "a task returns the ISR's buffer") && ok;
    ok = checkStatus(shell, isrResults.allocateSegment, Status::Ok, "a task returns the ISR's segment") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Return(isrResults.pool, isrResults.taskBuffer), Status::Ok, "Return") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(isrResults.pool), Status::Ok, "Delete the pool") && ok;
    ok = checkStatus(shell, heapAgent.Delete(isrResults.heap), Status::Ok, "Delete the heap") && ok;
    return ok;
}

DCOS_TARGET_TEST(memoryIsrTest, "memisr", "pools and heaps from an interrupt handler hold memory for the system",
                 memoryInInterrupts);

// The task that dies holding memory.
struct Holdings {
    ObjectId pool;            // The test task's pool.
    ObjectId heap;            // The test task's heap.
    ObjectId ownPool;         // A pool the dying task creates.
    ObjectId ownHeap;         // A heap the dying task creates.
    void* handedOver;         // A buffer it gives the test task before dying.
    bool ready;
};

Holdings holdings;
alignas(8) uint8_t dyingPoolArea[BufferPoolAgent::AreaBytes(8, 4)];
alignas(8) uint8_t dyingHeapArea[256];

void holdingEntry(uintptr_t suicide)
{
    Holdings& h = holdings;
    bool ok = bufferPoolAgent.Allocate(h.pool).ok() && bufferPoolAgent.Allocate(h.pool).ok();
    const dcos::Result<void*> given = bufferPoolAgent.Allocate(h.pool);
    ok = ok && given.ok() && bufferPoolAgent.XferOwnership(h.pool, given.value(), testTask()) == Status::Ok;
    h.handedOver = given.ok() ? given.value() : nullptr;
    // Segments spread over the heap, with free ones between them.
    void* segments[5];
    for (void*& segment : segments) {
        const dcos::Result<void*> allocated = heapAgent.Allocate(h.heap, 72);
        ok = ok && allocated.ok();
        segment = allocated.ok() ? allocated.value() : nullptr;
    }
    ok = ok && heapAgent.Return(h.heap, segments[1]) == Status::Ok && heapAgent.Return(h.heap, segments[3]) == Status::Ok;
    const dcos::Result<ObjectId> ownPool =
        bufferPoolAgent.Create(dyingPoolArea, sizeof dyingPoolArea, 8, "dying-pool", Visibility::Local);
    const dcos::Result<ObjectId> ownHeap = heapAgent.Create(dyingHeapArea, sizeof dyingHeapArea, nullptr, Visibility::Local);
    ok = ok && ownPool.ok() && ownHeap.ok() && bufferPoolAgent.Allocate(ownPool.value()).ok()
         && heapAgent.Allocate(ownHeap.value(), 100).ok();
    h.ownPool = ownPool.ok() ? ownPool.value() : ObjectId::null();
    h.ownHeap = ownHeap.ok() ? ownHeap.value() : ObjectId::null();
    h.ready = ok;
    if (suicide != 0) {
        (void)taskAgent.Delete(); // Ends with everything still held.
    }
    (void)taskAgent.ReceiveEvent(1u << 20, dcos::EventWait::Any, dcos::kWaitForever);
}

bool memoryRecovery(shell::Shell& shell)
{
    bool ok = true;
    for (uintptr_t suicide = 0; suicide < 2; ++suicide) {
        holdings = Holdings{};
        holdings.pool = bufferPoolAgent.Create(poolArea, sizeof poolArea, 32, nullptr, Visibility::Local).value();
        holdings.heap = heapAgent.Create(heapArea, sizeof heapArea, nullptr, Visibility::Local).value();
        const size_t poolsBefore = BufferPoolManager::usedCount();
        const size_t heapsBefore = HeapManager::usedCount();
        const ObjectId holder = spawn(suicide != 0 ? "holder-suicide" : "holder-killed", 10, holdingEntry, suicide);
        ok = check(shell, !holder.isNull() && holdings.ready, "the task allocated and created everything") && ok;
        if (suicide == 0) {
            ok = check(shell, poolStatistics(holdings.pool).freeBuffers == 5, "it holds three buffers") && ok;
            ok = check(shell, heapStatistics(holdings.heap).allocatedSegments == 3, "it holds three segments") && ok;
            ok = check(shell, heapStatistics(holdings.heap).freeSegments == 3, "with free segments between them") && ok;
            ok = check(shell, BufferPoolManager::usedCount() == poolsBefore + 1, "it owns a pool") && ok;
            ok = check(shell, HeapManager::usedCount() == heapsBefore + 1, "it owns a heap") && ok;
            ok = checkStatus(shell, taskAgent.KillTask(holder), Status::Ok, "KillTask") && ok;
        } else {
            (void)taskAgent.SleepFor(2000000); // Let the reaper finish the suicide.
        }
        const BufferPoolStatistics pool = poolStatistics(holdings.pool);
        const HeapStatistics heap = heapStatistics(holdings.heap);
        shell.print("%s: pool %lu of %lu free, heap %lu segments out, %lu free segments, largest %lu\r\n",
                    suicide != 0 ? "Delete" : "KillTask", static_cast<unsigned long>(pool.freeBuffers),
                    static_cast<unsigned long>(pool.totalBuffers), static_cast<unsigned long>(heap.allocatedSegments),
                    static_cast<unsigned long>(heap.freeSegments), static_cast<unsigned long>(heap.largestFreeSegment));
        ok = check(shell, pool.freeBuffers == 7, "its buffers came back, the handed-over one stayed out") && ok;
        ok = check(shell, heap.allocatedSegments == 0 && heap.freeSegments == 1
                              && heap.largestFreeSegment == sizeof heapArea - HeapAgent::kHeaderBytes,
                   "its segments came back and merged into one") && ok;
        ok = check(shell, BufferPoolManager::usedCount() == poolsBefore && HeapManager::usedCount() == heapsBefore,
                   "its pool and heap were deleted") && ok;
        ok = checkStatus(shell, bufferPoolAgent.Allocate(holdings.ownPool).status(), Status::StaleId,
                         "the dead task's pool id is stale") && ok;
        ok = checkStatus(shell, heapAgent.Allocate(holdings.ownHeap, 8).status(), Status::StaleId,
                         "the dead task's heap id is stale") && ok;
        ok = checkStatus(shell, bufferPoolAgent.Return(holdings.pool, holdings.handedOver), Status::Ok,
                         "the handed-over buffer is the test task's") && ok;
        ok = checkStatus(shell, bufferPoolAgent.Delete(holdings.pool), Status::Ok, "Delete the pool") && ok;
        ok = checkStatus(shell, heapAgent.Delete(holdings.heap), Status::Ok, "Delete the heap") && ok;
    }
    // The dead task's areas are the application's again.
    const dcos::Result<ObjectId> again =
        bufferPoolAgent.Create(dyingPoolArea, sizeof dyingPoolArea, 8, nullptr, Visibility::Local);
    ok = check(shell, again.ok(), "a new pool in the dead task's area") && ok;
    (void)bufferPoolAgent.Delete(again.value());
    return ok;
}

DCOS_TARGET_TEST(memoryRecoveryTest, "memrecovery", "a task that dies holding buffers and segments gives them back",
                 memoryRecovery);

} // namespace

} // namespace target_test
