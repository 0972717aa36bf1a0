// The lists of held memory on the target (HeldList.hpp): recovery of a
// killed task finds its buffers and segments from its lists, whichever way
// they came to it (Allocate, XferOwnership from another task) and whichever
// left it first (Return from the middle or the end of a list, XferOwnership
// away), without walking the pools and heaps; and a list damaged by a
// corrupted pool is noticed, and recovery then walks every pool, so the
// task's memory in the sound pools still comes back.
#include "KernelTestSupport.hpp"

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/HeapManager.hpp>

namespace target_test {

namespace {

using dcos::BufferPoolAgent;
using dcos::bufferPoolAgent;
using dcos::HeapAgent;
using dcos::heapAgent;
using dcos::ObjectId;
using dcos::Status;
using dcos::taskAgent;
using dcos::Visibility;
using dcos::internal::BufferPoolManager;
using dcos::internal::HeapManager;

constexpr size_t kBufferSize = 8;
alignas(8) uint8_t firstPoolArea[BufferPoolAgent::AreaBytes(kBufferSize, 8)];
alignas(8) uint8_t secondPoolArea[BufferPoolAgent::AreaBytes(kBufferSize, 4)];
alignas(8) uint8_t heapArea[1024];

// The worker runs one step each time the test posts it kStepEvent: the
// function in step, then finished(). It runs above the test task, so each
// step is over when PostEvent returns.
constexpr uint32_t kStepEvent = 1u << 0;
bool (*step)() = nullptr;
bool stepsOk = true;

void worker(uintptr_t)
{
    for (;;) {
        if (!taskAgent.ReceiveEvent(kStepEvent, dcos::EventWait::Any, dcos::kWaitForever).ok()) {
            stepsOk = false;
        }
        stepsOk = step() && stepsOk;
        finished();
    }
}

bool runStep(shell::Shell& shell, ObjectId task, bool (*what)())
{
    step = what;
    return checkStatus(shell, taskAgent.PostEvent(task, kStepEvent), Status::Ok, "PostEvent to the worker")
           && waitForDone(shell, 1);
}

size_t buffersOut(ObjectId pool)
{
    const dcos::BufferPoolStatistics statistics = bufferPoolAgent.GetStatistics(pool).value();
    return statistics.totalBuffers - statistics.freeBuffers;
}

size_t segmentsOut(ObjectId heap) { return heapAgent.GetStatistics(heap).value().allocatedSegments; }

// --- Memory changing hands in every way, then the holder killed.

ObjectId firstPool;
ObjectId secondPool;
ObjectId heap;
void* handedToTest = nullptr; // A buffer the worker gives the test task.

bool takeGiveAndHandOver()
{
    bool ok = true;
    const auto take = [&ok](ObjectId pool) {
        const dcos::Result<void*> buffer = bufferPoolAgent.Allocate(pool);
        ok = ok && buffer.ok();
        return buffer.ok() ? buffer.value() : nullptr;
    };
    const auto cut = [&ok](size_t bytes) {
        const dcos::Result<void*> segment = heapAgent.Allocate(heap, bytes);
        ok = ok && segment.ok();
        return segment.ok() ? segment.value() : nullptr;
    };
    // The buffer list becomes (newest first) b4 b3 b2 b1, the segment list s2 s1.
    (void)take(firstPool);
    void* const s1 = cut(24);
    void* const b2 = take(secondPool);
    (void)cut(40);
    void* const b3 = take(firstPool);
    (void)take(secondPool);
    ok = bufferPoolAgent.Return(secondPool, b2) == Status::Ok && ok;                 // From the middle,
    ok = heapAgent.Return(heap, s1) == Status::Ok && ok;                             // from the end,
    ok = bufferPoolAgent.XferOwnership(firstPool, b3, testTask()) == Status::Ok && ok; // and handed away.
    handedToTest = b3;
    return ok;
}

bool handsChanging(shell::Shell& shell)
{
    firstPool = bufferPoolAgent.Create(firstPoolArea, sizeof firstPoolArea, kBufferSize, nullptr, Visibility::Local).value();
    secondPool =
        bufferPoolAgent.Create(secondPoolArea, sizeof secondPoolArea, kBufferSize, nullptr, Visibility::Local).value();
    heap = heapAgent.Create(heapArea, sizeof heapArea, nullptr, Visibility::Local).value();
    const uint32_t poolWalks = BufferPoolManager::recoveryWalks();
    const uint32_t heapWalks = HeapManager::recoveryWalks();
    stepsOk = true;
    const ObjectId holder = spawn("holder", 10, worker);
    bool ok = check(shell, !holder.isNull(), "the worker started");
    ok = runStep(shell, holder, takeGiveAndHandOver) && check(shell, stepsOk, "every call of the worker succeeded") && ok;
    // The test task's own buffer, and a segment it hands to the worker.
    void* const own = bufferPoolAgent.Allocate(firstPool).value();
    void* const given = heapAgent.Allocate(heap, 16).value();
    ok = checkStatus(shell, heapAgent.XferOwnership(heap, given, holder), Status::Ok, "hand a segment to the worker")
         && ok;
    shell.print("before: first pool %u out, second %u, heap %u segments\r\n", unsigned(buffersOut(firstPool)),
                unsigned(buffersOut(secondPool)), unsigned(segmentsOut(heap)));
    ok = check(shell, buffersOut(firstPool) == 3 && buffersOut(secondPool) == 1 && segmentsOut(heap) == 2,
               "the worker holds b1, b4, s2 and the segment handed to it") && ok;
    ok = checkStatus(shell, taskAgent.KillTask(holder), Status::Ok, "KillTask") && ok;
    shell.print("after: first pool %u out, second %u, heap %u segments; walks %u %u\r\n",
                unsigned(buffersOut(firstPool)), unsigned(buffersOut(secondPool)), unsigned(segmentsOut(heap)),
                unsigned(BufferPoolManager::recoveryWalks() - poolWalks),
                unsigned(HeapManager::recoveryWalks() - heapWalks));
    ok = check(shell, buffersOut(firstPool) == 2 && buffersOut(secondPool) == 0 && segmentsOut(heap) == 0,
               "everything the worker held came back, nothing else") && ok;
    ok = check(shell, BufferPoolManager::recoveryWalks() == poolWalks && HeapManager::recoveryWalks() == heapWalks,
               "recovery found it from the lists, without a walk") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Return(firstPool, handedToTest), Status::Ok,
                     "the buffer handed to the test task is its own") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Return(firstPool, own), Status::Ok, "so is the one it took") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(firstPool), Status::Ok, "Delete the first pool") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(secondPool), Status::Ok, "Delete the second pool") && ok;
    ok = checkStatus(shell, heapAgent.Delete(heap), Status::Ok, "Delete the heap") && ok;
    return ok;
}

DCOS_TARGET_TEST(heldListsTest, "heldlists", "recovery finds a killed task's buffers and segments from its lists",
                 handsChanging);

// --- A list through a pool that turns out corrupted.

ObjectId soundPool;
ObjectId brokenPool;

bool takeFromBoth()
{
    // The list becomes (newest first) c3 c2 c1: c1's predecessor is in the
    // pool about to break.
    return bufferPoolAgent.Allocate(soundPool).ok() && bufferPoolAgent.Allocate(brokenPool).ok()
           && bufferPoolAgent.Allocate(brokenPool).ok();
}

void* lastSound = nullptr;

bool giveBackAndTakeAgain()
{
    // A buffer of the sound pool goes first on the list, before c3, which no
    // longer resolves: the list is lost, and the buffer is on none. It is
    // returned all the same, and taken again.
    void* const buffer = bufferPoolAgent.Allocate(soundPool).value();
    const bool returned = bufferPoolAgent.Return(soundPool, buffer) == Status::Ok;
    const dcos::Result<void*> again = bufferPoolAgent.Allocate(soundPool);
    lastSound = again.ok() ? again.value() : nullptr;
    return returned && again.ok();
}

bool lostList(shell::Shell& shell)
{
    soundPool = bufferPoolAgent.Create(firstPoolArea, sizeof firstPoolArea, kBufferSize, nullptr, Visibility::Local).value();
    brokenPool =
        bufferPoolAgent.Create(secondPoolArea, sizeof secondPoolArea, kBufferSize, nullptr, Visibility::Local).value();
    const uint32_t walks = BufferPoolManager::recoveryWalks();
    stepsOk = true;
    const ObjectId holder = spawn("holder", 10, worker);
    bool ok = check(shell, !holder.isNull(), "the worker started");
    ok = runStep(shell, holder, takeFromBoth) && check(shell, stepsOk, "the worker took three buffers") && ok;
    // A stray write over the state word of the broken pool's free-list head
    // (buffer 2: 0 and 1 are out), found by the next Allocate.
    reinterpret_cast<volatile uint32_t*>(secondPoolArea)[2] = 0x12345678;
    ok = checkStatus(shell, bufferPoolAgent.Allocate(brokenPool).status(), Status::Corrupted,
                     "the broken pool is disabled") && ok;
    ok = runStep(shell, holder, giveBackAndTakeAgain)
         && check(shell, stepsOk, "the worker returned and took buffers of the sound pool") && ok;
    ok = check(shell, buffersOut(soundPool) == 2, "it holds two buffers of the sound pool") && ok;
    ok = checkStatus(shell, taskAgent.KillTask(holder), Status::Ok, "KillTask") && ok;
    shell.print("after: sound pool %u out, walks %u\r\n", unsigned(buffersOut(soundPool)),
                unsigned(BufferPoolManager::recoveryWalks() - walks));
    ok = check(shell, buffersOut(soundPool) == 0, "its buffers of the sound pool came back") && ok;
    ok = check(shell, BufferPoolManager::recoveryWalks() == walks + 1, "by a walk over every pool") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(brokenPool), Status::Ok, "Delete the broken pool") && ok;
    ok = checkStatus(shell, bufferPoolAgent.Delete(soundPool), Status::Ok, "Delete the sound pool") && ok;
    return ok;
}

DCOS_TARGET_TEST(lostListTest, "heldlost",
                 "a held list through a corrupted pool is lost, and recovery walks every pool instead", lostList);

} // namespace

} // namespace target_test
