// The semaphore agent on the target: binary and counting semaphores,
// time-outs, deletion and holder death, and priority inheritance with one
// holder of several semaphores (seed 7.11).
#include "KernelTestSupport.hpp"

#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/TaskManager.hpp>

#include <arch_x86/Cpu.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::SemaphoreAttributes;
using dcos::SemaphoreKind;
using dcos::Status;
using dcos::semaphoreAgent;
using dcos::taskAgent;

constexpr uint64_t kMillisecond = 1000000;
constexpr uint32_t kGoEvent = 1u << 1;

ObjectId createSemaphore(SemaphoreKind kind, uint32_t initial, bool inheritance, uint32_t maximum = 0xFFFFFFFF)
{
    SemaphoreAttributes attributes;
    attributes.kind = kind;
    attributes.initialCount = initial;
    attributes.maximumCount = maximum;
    attributes.priorityInheritance = inheritance;
    const dcos::Result<ObjectId> id = semaphoreAgent.Create(attributes);
    return id.ok() ? id.value() : ObjectId::null();
}

// The priority a task runs at now, inheritance included.
uint8_t runningPriority(ObjectId task) { return dcos::internal::TaskManager::resolve(task).value()->priority; }

// --- Basics ---------------------------------------------------------------------

ObjectId shared;
volatile Status waiterResult = Status::Ok;

void acquireAndReportEntry(uintptr_t timeout)
{
    waiterResult = semaphoreAgent.Acquire(shared, timeout);
    finished();
    (void)taskAgent.ReceiveEvent(1u << 20, dcos::EventWait::Any, dcos::kWaitForever);
}

bool basics(shell::Shell& shell)
{
    const ObjectId binary = createSemaphore(SemaphoreKind::Binary, 1, false);
    bool ok = check(shell, !binary.isNull(), "create a binary semaphore");
    ok = checkStatus(shell, semaphoreAgent.Acquire(binary, dcos::kPoll), Status::Ok, "acquire") && ok;
    ok = checkStatus(shell, semaphoreAgent.Acquire(binary, dcos::kWaitForever), Status::Deadlock,
                     "the holder acquiring again") && ok;
    ok = check(shell, semaphoreAgent.GetHolder(binary).value() == taskAgent.IdOfSelf(), "GetHolder") && ok;
    ok = checkStatus(shell, semaphoreAgent.Release(binary), Status::Ok, "release") && ok;
    ok = checkStatus(shell, semaphoreAgent.Release(binary), Status::NotOwner, "release when not held") && ok;

    // Another task cannot release what this one holds.
    shared = binary;
    (void)semaphoreAgent.Acquire(binary, dcos::kPoll);
    const ObjectId other = spawn("sem-poller", 10, acquireAndReportEntry, dcos::kPoll);
    ok = ok && waitForDone(shell, 1);
    ok = checkStatus(shell, waiterResult, Status::WouldBlock, "a poll of a held semaphore") && ok;
    (void)taskAgent.KillTask(other);

    // Time-out.
    const uint64_t before = dcos::timerAgent.Uptime();
    const ObjectId timed = spawn("sem-timed", 10, acquireAndReportEntry, 10 * kMillisecond);
    ok = ok && waitForDone(shell, 1);
    const uint64_t waited = dcos::timerAgent.Uptime() - before;
    ok = checkStatus(shell, waiterResult, Status::Timeout, "a timed acquire of a held semaphore") && ok;
    ok = check(shell, waited >= 10 * kMillisecond && waited <= 13 * kMillisecond, "time-out of 10 ms") && ok;
    (void)taskAgent.KillTask(timed);
    (void)semaphoreAgent.Release(binary);

    // Counting semaphore with a maximum.
    const ObjectId counting = createSemaphore(SemaphoreKind::Counting, 2, false, 3);
    ok = check(shell, !counting.isNull(), "create a counting semaphore") && ok;
    ok = checkStatus(shell, semaphoreAgent.Acquire(counting, dcos::kPoll), Status::Ok, "take 1 of 2") && ok;
    ok = checkStatus(shell, semaphoreAgent.Acquire(counting, dcos::kPoll), Status::Ok, "take 2 of 2") && ok;
    ok = checkStatus(shell, semaphoreAgent.Acquire(counting, dcos::kPoll), Status::WouldBlock, "none left") && ok;
    for (int i = 0; i < 3; ++i) {
        (void)semaphoreAgent.Release(counting);
    }
    ok = check(shell, semaphoreAgent.GetCount(counting).value() == 3, "count 3") && ok;
    ok = checkStatus(shell, semaphoreAgent.Release(counting), Status::InvalidArgument, "beyond the maximum") && ok;

    // Argument and id errors.
    SemaphoreAttributes bad;
    bad.kind = SemaphoreKind::Counting;
    bad.priorityInheritance = true;
    ok = checkStatus(shell, semaphoreAgent.Create(bad).status(), Status::InvalidArgument,
                     "inheritance on a counting semaphore") && ok;
    bad.kind = SemaphoreKind::Binary;
    bad.priorityInheritance = false;
    bad.initialCount = 2;
    ok = checkStatus(shell, semaphoreAgent.Create(bad).status(), Status::InvalidArgument, "binary count 2") && ok;
    ok = checkStatus(shell, semaphoreAgent.Acquire(taskAgent.IdOfSelf(), dcos::kPoll), Status::WrongType,
                     "a task id") && ok;
    ok = checkStatus(shell, semaphoreAgent.Acquire(ObjectId(7, dcos::ObjectType::Semaphore, 1), dcos::kPoll),
                     Status::Remote, "another node's semaphore") && ok;
    ok = checkStatus(shell, semaphoreAgent.Delete(counting), Status::Ok, "delete") && ok;
    ok = checkStatus(shell, semaphoreAgent.Acquire(counting, dcos::kPoll), Status::StaleId, "use after delete") && ok;
    ok = checkStatus(shell, semaphoreAgent.Delete(binary), Status::Ok, "delete the binary one") && ok;
    return ok;
}

DCOS_TARGET_TEST(semaphoreBasicsTest, "semaphores", "binary and counting semaphores, time-outs and errors", basics);

// --- Deletion and holder death ------------------------------------------------------

void holdForeverEntry(uintptr_t)
{
    (void)semaphoreAgent.Acquire(shared, dcos::kPoll);
    finished();
    (void)taskAgent.ReceiveEvent(1u << 20, dcos::EventWait::Any, dcos::kWaitForever);
}

volatile Status waitResults[3];

void waitResultEntry(uintptr_t index)
{
    waitResults[index] = semaphoreAgent.Acquire(shared, dcos::kWaitForever);
    finished();
}

bool deletionAndDeath(shell::Shell& shell)
{
    bool ok = true;
    for (int round = 0; round < 2; ++round) {
        shared = createSemaphore(SemaphoreKind::Binary, 1, true);
        const ObjectId holder = spawn("sem-holder", 20, holdForeverEntry);
        ok = waitForDone(shell, 1) && ok;
        for (uintptr_t i = 0; i < 3; ++i) {
            waitResults[i] = Status::Ok;
            spawn("sem-waiter", static_cast<uint8_t>(10 + i), waitResultEntry, i);
        }
        const Status expected = round == 0 ? Status::Deleted : Status::Abandoned;
        if (round == 0) {
            ok = checkStatus(shell, semaphoreAgent.Delete(shared), Status::Ok, "Delete with waiters") && ok;
        } else {
            ok = checkStatus(shell, taskAgent.KillTask(holder), Status::Ok, "KillTask of the holder") && ok;
        }
        ok = waitForDone(shell, 3) && ok;
        for (int i = 0; i < 3; ++i) {
            ok = checkStatus(shell, waitResults[i], expected, round == 0 ? "waiter of a deleted semaphore"
                                                                         : "waiter of a dead holder") && ok;
        }
        if (round == 0) {
            (void)taskAgent.KillTask(holder);
        } else {
            ok = checkStatus(shell, semaphoreAgent.Acquire(shared, dcos::kPoll), Status::Ok,
                             "the abandoned semaphore is free again") && ok;
            (void)semaphoreAgent.Release(shared);
            (void)semaphoreAgent.Delete(shared);
        }
    }
    return ok;
}

DCOS_TARGET_TEST(semaphoreDeathTest, "semdelete", "deleting a semaphore or killing its holder wakes every waiter",
                 deletionAndDeath);

// --- Priority inheritance -----------------------------------------------------------

ObjectId semaphoreA;
ObjectId semaphoreB;
volatile uint8_t lowPriorities[4];

void lowEntry(uintptr_t)
{
    (void)semaphoreAgent.Acquire(semaphoreA, dcos::kPoll);
    Trace::record('l');
    (void)taskAgent.ReceiveEvent(kGoEvent, dcos::EventWait::Any, dcos::kWaitForever);
    spin(5 * kMillisecond);
    Trace::record('r');
    (void)semaphoreAgent.Release(semaphoreA);
    Trace::record('L');
    finished();
}

void highEntry(uintptr_t)
{
    (void)semaphoreAgent.Acquire(semaphoreA, dcos::kWaitForever);
    Trace::record('H');
    (void)semaphoreAgent.Release(semaphoreA);
    finished();
}

void mediumEntry(uintptr_t)
{
    (void)taskAgent.ReceiveEvent(kGoEvent, dcos::EventWait::Any, dcos::kWaitForever);
    spin(20 * kMillisecond);
    Trace::record('M');
    finished();
}

bool lowMediumHigh(shell::Shell& shell, bool inheritance, const char* expected)
{
    Trace::clear();
    semaphoreA = createSemaphore(SemaphoreKind::Binary, 1, inheritance);
    const ObjectId low = spawn("low", 20, lowEntry);    // Takes A, waits for go.
    const ObjectId high = spawn("high", 5, highEntry);  // Blocks on A.
    const ObjectId medium = spawn("medium", 10, mediumEntry);
    bool ok = check(shell, !low.isNull() && !high.isNull() && !medium.isNull(), "create low, medium, high");
    ok = check(shell, runningPriority(low) == (inheritance ? 5 : 20), "low runs at high's priority only with inheritance") && ok;
    {
        HoldScheduling hold;
        (void)taskAgent.PostEvent(medium, kGoEvent);
        (void)taskAgent.PostEvent(low, kGoEvent);
    }
    ok = waitForDone(shell, 3) && ok;
    ok = Trace::expect(shell, expected) && ok;
    (void)semaphoreAgent.Delete(semaphoreA);
    return ok;
}

// The holder of two inheriting semaphores keeps the more urgent waiter's
// priority until it releases that semaphore, then the other's.
void doubleHolderEntry(uintptr_t)
{
    (void)semaphoreAgent.Acquire(semaphoreA, dcos::kPoll);
    (void)semaphoreAgent.Acquire(semaphoreB, dcos::kPoll);
    finished();
    (void)taskAgent.ReceiveEvent(kGoEvent, dcos::EventWait::Any, dcos::kWaitForever);
    lowPriorities[0] = runningPriority(taskAgent.IdOfSelf());
    (void)semaphoreAgent.Release(semaphoreB);
    lowPriorities[1] = runningPriority(taskAgent.IdOfSelf());
    (void)semaphoreAgent.Release(semaphoreA);
    lowPriorities[2] = runningPriority(taskAgent.IdOfSelf());
    finished();
}

void waitOnEntry(uintptr_t which)
{
    const ObjectId semaphore = which == 0 ? semaphoreA : semaphoreB;
    (void)semaphoreAgent.Acquire(semaphore, dcos::kWaitForever);
    (void)semaphoreAgent.Release(semaphore);
    finished();
}

bool twoSemaphores(shell::Shell& shell)
{
    semaphoreA = createSemaphore(SemaphoreKind::Binary, 1, true);
    semaphoreB = createSemaphore(SemaphoreKind::Binary, 1, true);
    const ObjectId holder = spawn("holder", 20, doubleHolderEntry);
    bool ok = waitForDone(shell, 1);
    spawn("wait-a", 8, waitOnEntry, 0);  // Lends 8 through A.
    ok = check(shell, runningPriority(holder) == 8, "one waiter: the holder runs at 8") && ok;
    spawn("wait-b", 5, waitOnEntry, 1);  // Lends 5 through B.
    ok = check(shell, runningPriority(holder) == 5, "two waiters: the holder runs at 5") && ok;
    (void)taskAgent.PostEvent(holder, kGoEvent);
    ok = waitForDone(shell, 3) && ok;
    shell.print("holder priority: %u holding both, %u after releasing B, %u after releasing A\r\n", lowPriorities[0],
                lowPriorities[1], lowPriorities[2]);
    ok = check(shell, lowPriorities[0] == 5 && lowPriorities[1] == 8 && lowPriorities[2] == 20,
               "the holder drops back one release at a time") && ok;
    (void)semaphoreAgent.Delete(semaphoreA);
    (void)semaphoreAgent.Delete(semaphoreB);
    return ok;
}

void timedWaitEntry(uintptr_t)
{
    (void)semaphoreAgent.Acquire(semaphoreA, 5 * kMillisecond);
    finished();
}

bool inheritance(shell::Shell& shell)
{
    // Without inheritance medium starves low, and so high ("priority
    // inversion"); with it low finishes its hold first.
    bool ok = lowMediumHigh(shell, false, "lMrHL");
    ok = lowMediumHigh(shell, true, "lrHML") && ok;
    ok = twoSemaphores(shell) && ok;

    // A waiter that times out stops lending its priority.
    semaphoreA = createSemaphore(SemaphoreKind::Binary, 1, true);
    (void)semaphoreAgent.Acquire(semaphoreA, dcos::kPoll);
    const ObjectId self = taskAgent.IdOfSelf();
    const uint8_t own = runningPriority(self);
    spawn("timed-waiter", 3, timedWaitEntry);
    ok = check(shell, runningPriority(self) == 3, "a waiter lends its priority") && ok;
    ok = waitForDone(shell, 1) && ok;
    ok = check(shell, runningPriority(self) == own, "after its time-out the holder drops back") && ok;
    (void)semaphoreAgent.Release(semaphoreA);
    (void)semaphoreAgent.Delete(semaphoreA);
    return ok;
}

DCOS_TARGET_TEST(inheritanceTest, "inherit", "priority inheritance: low/medium/high and a holder of two semaphores",
                 inheritance);

} // namespace

} // namespace target_test
