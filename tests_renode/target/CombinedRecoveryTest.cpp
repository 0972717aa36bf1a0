// Resource recovery across the agents (issue 4): a task that dies holding a
// pool buffer, a heap segment, a semaphore and a port with queued messages
// gives every one of them back, whether it is killed or ends by itself.
#include "KernelTestSupport.hpp"

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/internal/PortManager.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::bufferPoolAgent;
using dcos::heapAgent;
using dcos::messagePortAgent;
using dcos::semaphoreAgent;
using dcos::taskAgent;

alignas(8) uint8_t poolArea[dcos::BufferPoolAgent::AreaBytes(32, 8)];
alignas(8) uint8_t heapArea[4096];

ObjectId pool;
ObjectId heap;
ObjectId semaphore;
ObjectId ownedPort; // Written by the task before it reports, read after.
volatile bool holding = false;

void holdingEntry(uintptr_t endsItself)
{
    const bool buffer = bufferPoolAgent.Allocate(pool).ok();
    const bool segment = heapAgent.Allocate(heap, 300).ok();
    const bool held = semaphoreAgent.Acquire(semaphore, dcos::kPoll) == Status::Ok;
    const dcos::Result<ObjectId> port = messagePortAgent.Create(nullptr, dcos::Visibility::Local);
    bool queued = port.ok();
    dcos::Message message{};
    for (int i = 0; i < 5 && queued; ++i) {
        queued = messagePortAgent.Send(port.value(), message, 0) == Status::Ok;
    }
    ownedPort = port.ok() ? port.value() : ObjectId::null();
    holding = buffer && segment && held && queued;
    finished();
    if (endsItself == 0) {
        (void)taskAgent.ReceiveEvent(1u << 20, dcos::EventWait::Any, dcos::kWaitForever);
    }
}

bool combinedRecovery(shell::Shell& shell)
{
    pool = bufferPoolAgent.Create(poolArea, sizeof poolArea, 32, "rec-pool", dcos::Visibility::Local).value();
    heap = heapAgent.Create(heapArea, sizeof heapArea, "rec-heap", dcos::Visibility::Local).value();
    dcos::SemaphoreAttributes attributes;
    attributes.priorityInheritance = true;
    semaphore = semaphoreAgent.Create(attributes).value();
    bool ok = check(shell, !pool.isNull() && !heap.isNull() && !semaphore.isNull(), "create pool, heap, semaphore");
    const uint32_t poolFree = bufferPoolAgent.GetStatistics(pool).value().freeBuffers;
    const uint32_t heapFree = heapAgent.GetStatistics(heap).value().freeBytes;
    const size_t buffersFree = dcos::internal::PortManager::bufferCounts().free;

    for (uintptr_t endsItself = 0; endsItself < 2; ++endsItself) {
        holding = false;
        const ObjectId task = spawn(endsItself == 0 ? "holder-killed" : "holder-ends", 10, holdingEntry, endsItself);
        ok = waitForDone(shell, 1) && ok;
        ok = check(shell, holding, "the task holds a buffer, a segment, the semaphore and a port with 5 messages") && ok;
        if (endsItself == 0) {
            ok = checkStatus(shell, taskAgent.KillTask(task), Status::Ok, "KillTask") && ok;
        } else {
            (void)taskAgent.SleepFor(2000000); // It has ended; let the reaper run.
        }
        const uint32_t poolNow = bufferPoolAgent.GetStatistics(pool).value().freeBuffers;
        const uint32_t heapNow = heapAgent.GetStatistics(heap).value().freeBytes;
        const size_t buffersNow = dcos::internal::PortManager::bufferCounts().free;
        shell.print("%s: pool %lu->%lu free, heap %lu->%lu bytes free, message buffers %lu->%lu free\r\n",
                    endsItself == 0 ? "killed" : "ended", static_cast<unsigned long>(poolFree),
                    static_cast<unsigned long>(poolNow), static_cast<unsigned long>(heapFree),
                    static_cast<unsigned long>(heapNow), static_cast<unsigned long>(buffersFree),
                    static_cast<unsigned long>(buffersNow));
        ok = check(shell, poolNow == poolFree, "the pool buffer came back") && ok;
        ok = check(shell, heapNow == heapFree, "the heap segment came back") && ok;
        ok = check(shell, buffersNow == buffersFree, "the queued messages' buffers came back") && ok;
        ok = check(shell, semaphoreAgent.GetHolder(semaphore).value().isNull() &&
                              semaphoreAgent.GetCount(semaphore).value() == 1,
                   "the semaphore is free again") && ok;
        ok = checkStatus(shell, messagePortAgent.Send(ownedPort, dcos::Message{}, 0), Status::StaleId,
                         "the dead task's port is gone") && ok;
    }
    ok = checkStatus(shell, bufferPoolAgent.Delete(pool), Status::Ok, "delete the pool") && ok;
    ok = checkStatus(shell, heapAgent.Delete(heap), Status::Ok, "delete the heap") && ok;
    ok = checkStatus(shell, semaphoreAgent.Delete(semaphore), Status::Ok, "delete the semaphore") && ok;
    return ok;
}

} // namespace

DCOS_TARGET_TEST(combinedRecoveryTest, "recoverall",
                 "a dying task gives back a pool buffer, a heap segment, a semaphore and a port", combinedRecovery);

} // namespace target_test
