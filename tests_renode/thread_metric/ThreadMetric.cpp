// The Thread-Metric RTOS benchmark suite, written for DCOS from its published
// description (the eight tests of Express Logic's Thread-Metric).
//
// Thread-Metric runs each test for a fixed interval and reports how many
// iterations completed. Here the emulator counts retired instructions
// exactly, so each test runs a fixed number of iterations and reports the
// instructions per iteration, a figure independent of the interval length
// and of the host machine. The tests keep the suite's structure:
//   basic processing       one task, a fixed computation (the calibration);
//   cooperative scheduling five equal tasks passing the CPU with Yield;
//   preemptive scheduling  five tasks of rising priority, each resuming the
//                          next and suspending itself;
//   interrupt processing   a task raises an interrupt whose handler releases
//                          a semaphore the task then acquires;
//   interrupt preemption   the handler resumes a more urgent task, which runs
//                          at once and suspends itself;
//   message processing     a task sends a 16-byte message and receives it;
//   synchronisation        a task acquires and releases a semaphore;
//   memory allocation      a task allocates and returns a 128-byte buffer.
//
// The console command 'threadmetric' runs them; tests_renode/thread_metric/
// run_thread_metric.py boots the bench image and records the results.
#include <dcos/BufferPoolAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SchedulerAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <shell/Shell.hpp>

#include <stdint.h>

namespace thread_metric {

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::messagePortAgent;
using dcos::schedulerAgent;
using dcos::semaphoreAgent;
using dcos::systemAgent;
using dcos::taskAgent;

constexpr uint32_t kIterations = 2000;
constexpr uint32_t kDoneEvent = 1u << 29;
constexpr uint64_t kWaitLimitNs = 5000000000ull;
// An interrupt line no device uses; the tests raise its vector by software.
constexpr unsigned kSpareLine = 5;

inline uint64_t readTimeStampCounter()
{
    uint32_t low;
    uint32_t high;
    asm volatile("rdtsc" : "=a"(low), "=d"(high));
    return (uint64_t{high} << 32) | low;
}

inline void raiseSpareInterrupt() { asm volatile("int $0x25" ::: "memory"); }

// Shared by the multi-task tests: the workers count iterations together and
// the one that completes the last stops the clock.
ObjectId runner;
volatile uint32_t iterationsDone = 0;
volatile uint64_t startedAt = 0;
volatile uint64_t stoppedAt = 0;
volatile uint32_t workersDone = 0;

void resetRun()
{
    runner = taskAgent.IdOfSelf();
    iterationsDone = 0;
    stoppedAt = 0;
    workersDone = 0;
}

// Counts one iteration; true when the run is complete.
bool countIteration()
{
    const uint32_t done = iterationsDone + 1;
    iterationsDone = done;
    if (done == kIterations) {
        stoppedAt = readTimeStampCounter();
    }
    return done >= kIterations;
}

void workerFinished()
{
    workersDone = workersDone + 1;
    (void)taskAgent.PostEvent(runner, kDoneEvent);
}

// Waits until count workers have finished; false on a time-out.
bool waitForWorkers(uint32_t count)
{
    while (workersDone < count) {
        if (!taskAgent.ReceiveEvent(kDoneEvent, dcos::EventWait::Any, kWaitLimitNs).ok() && workersDone < count) {
            return false;
        }
    }
    return true;
}

ObjectId spawn(uint8_t priority, dcos::TaskEntry entry, uintptr_t argument)
{
    dcos::TaskAttributes attributes;
    attributes.name = "tm-worker";
    attributes.priority = priority;
    attributes.stackSize = 4096;
    const dcos::Result<ObjectId> id = taskAgent.Create(attributes, entry, argument);
    return id.ok() ? id.value() : ObjectId::null();
}

// Runs with the runner at priority 0 so that workers created inside wait;
// the clock starts as the runner drops back and lets them go.
struct Held {
    Held() : self(taskAgent.IdOfSelf()), own(taskAgent.GetPriority(self).value()) { (void)taskAgent.ChangePriority(self, 0); }
    void release()
    {
        startedAt = readTimeStampCounter();
        (void)taskAgent.ChangePriority(self, own);
    }
    ObjectId self;
    uint8_t own;
};

// A test returns the instructions for kIterations, or 0 when it failed.
using TestFunction = uint64_t (*)();

// --- Basic processing (calibration) ----------------------------------------------

volatile uint32_t workArea[64];

uint64_t basicProcessing()
{
    const uint64_t start = readTimeStampCounter();
    for (uint32_t iteration = 0; iteration < kIterations; ++iteration) {
        for (uint32_t i = 0; i < 64; ++i) {
            workArea[i] = (workArea[i] + iteration) ^ i;
        }
    }
    return readTimeStampCounter() - start;
}

// --- Cooperative scheduling --------------------------------------------------------

void cooperativeEntry(uintptr_t)
{
    while (!countIteration()) {
        (void)schedulerAgent.Yield();
    }
    workerFinished();
}

uint64_t cooperativeScheduling()
{
    resetRun();
    Held held;
    for (uintptr_t i = 0; i < 5; ++i) {
        if (spawn(10, cooperativeEntry, i).isNull()) {
            return 0;
        }
    }
    held.release();
    return waitForWorkers(5) ? stoppedAt - startedAt : 0;
}

// --- Preemptive scheduling ----------------------------------------------------------

ObjectId chain[5];

// Worker 4 (least urgent) loops; each resume makes the next, more urgent
// worker run at once; the most urgent counts and suspends itself, and the
// others suspend in turn back down the chain.
constexpr uint32_t kStartEvent = 1u << 28;

void preemptiveEntry(uintptr_t index)
{
    if (index == 4) {
        (void)taskAgent.ReceiveEvent(kStartEvent, dcos::EventWait::Any, dcos::kWaitForever);
    }
    for (;;) {
        if (index == 4) {
            if (countIteration()) {
                workerFinished();
                return;
            }
            (void)taskAgent.Resume(chain[3]);
        } else {
            if (index > 0) {
                (void)taskAgent.Resume(chain[index - 1]);
            }
            (void)taskAgent.Suspend(chain[index]);
        }
    }
}

uint64_t preemptiveScheduling()
{
    resetRun();
    {
        Held held;
        for (uintptr_t i = 0; i < 5; ++i) {
            chain[i] = spawn(static_cast<uint8_t>(10 + i), preemptiveEntry, i);
            if (chain[i].isNull()) {
                return 0;
            }
        }
        // Dropping back lets workers 0-3 suspend themselves and worker 4
        // wait for the start; then the clock starts.
        (void)taskAgent.ChangePriority(held.self, held.own);
    }
    startedAt = readTimeStampCounter();
    (void)taskAgent.PostEvent(chain[4], kStartEvent);
    const bool ok = waitForWorkers(1);
    for (int i = 0; i < 4; ++i) {
        (void)taskAgent.KillTask(chain[i]);
    }
    return ok ? stoppedAt - startedAt : 0;
}

// --- Interrupt processing ------------------------------------------------------------

ObjectId interruptSemaphore;

void releaseFromInterrupt(void*) { (void)semaphoreAgent.Release(interruptSemaphore); }

uint64_t interruptProcessing()
{
    dcos::SemaphoreAttributes attributes;
    attributes.kind = dcos::SemaphoreKind::Counting;
    attributes.initialCount = 0;
    const dcos::Result<ObjectId> semaphore = semaphoreAgent.Create(attributes);
    if (!semaphore.ok()) {
        return 0;
    }
    interruptSemaphore = semaphore.value();
    if (systemAgent.InstallISR(kSpareLine, releaseFromInterrupt, nullptr) != Status::Ok) {
        (void)semaphoreAgent.Delete(interruptSemaphore);
        return 0;
    }
    bool ok = true;
    const uint64_t start = readTimeStampCounter();
    for (uint32_t i = 0; i < kIterations && ok; ++i) {
        raiseSpareInterrupt();
        ok = semaphoreAgent.Acquire(interruptSemaphore, dcos::kPoll) == Status::Ok;
    }
    const uint64_t elapsed = readTimeStampCounter() - start;
    (void)systemAgent.RemoveISR(kSpareLine);
    (void)semaphoreAgent.Delete(interruptSemaphore);
    return ok ? elapsed : 0;
}

// --- Interrupt preemption processing -----------------------------------------------

ObjectId preemptingTask;
volatile uint32_t preemptions = 0;

void resumeFromInterrupt(void*) { (void)taskAgent.Resume(preemptingTask); }

void preemptingEntry(uintptr_t)
{
    // It runs before Create returns, so it must not rely on preemptingTask yet.
    const ObjectId self = taskAgent.IdOfSelf();
    for (;;) {
        (void)taskAgent.Suspend(self);
        preemptions = preemptions + 1;
    }
}

uint64_t interruptPreemptionProcessing()
{
    preemptions = 0;
    preemptingTask = spawn(5, preemptingEntry, 0); // Runs at once and suspends itself.
    if (preemptingTask.isNull() || systemAgent.InstallISR(kSpareLine, resumeFromInterrupt, nullptr) != Status::Ok) {
        return 0;
    }
    const uint64_t start = readTimeStampCounter();
    for (uint32_t i = 0; i < kIterations; ++i) {
        raiseSpareInterrupt(); // The handler readies the task; it runs before this loop goes on.
    }
    const uint64_t elapsed = readTimeStampCounter() - start;
    (void)systemAgent.RemoveISR(kSpareLine);
    (void)taskAgent.KillTask(preemptingTask);
    return preemptions == kIterations ? elapsed : 0;
}

// --- Message processing --------------------------------------------------------------

uint64_t messageProcessing()
{
    const dcos::Result<ObjectId> port = messagePortAgent.Create("tm-port", dcos::Visibility::Local);
    if (!port.ok()) {
        return 0;
    }
    dcos::Message message{};
    bool ok = true;
    const uint64_t start = readTimeStampCounter();
    for (uint32_t i = 0; i < kIterations && ok; ++i) {
        message.bytes[0] = static_cast<uint8_t>(i);
        ok = messagePortAgent.Send(port.value(), message, 0) == Status::Ok &&
             messagePortAgent.Receive(port.value(), message, dcos::kPoll) == Status::Ok &&
             message.bytes[0] == static_cast<uint8_t>(i);
    }
    const uint64_t elapsed = readTimeStampCounter() - start;
    (void)messagePortAgent.Delete(port.value());
    return ok ? elapsed : 0;
}

// --- Synchronisation processing ------------------------------------------------------

uint64_t synchronisationProcessing()
{
    dcos::SemaphoreAttributes attributes;
    const dcos::Result<ObjectId> semaphore = semaphoreAgent.Create(attributes);
    if (!semaphore.ok()) {
        return 0;
    }
    bool ok = true;
    const uint64_t start = readTimeStampCounter();
    for (uint32_t i = 0; i < kIterations && ok; ++i) {
        ok = semaphoreAgent.Acquire(semaphore.value(), dcos::kPoll) == Status::Ok &&
             semaphoreAgent.Release(semaphore.value()) == Status::Ok;
    }
    const uint64_t elapsed = readTimeStampCounter() - start;
    (void)semaphoreAgent.Delete(semaphore.value());
    return ok ? elapsed : 0;
}

// --- Memory allocation ---------------------------------------------------------------

alignas(8) uint8_t poolArea[16 * 128];

uint64_t memoryAllocation()
{
    const dcos::Result<ObjectId> pool =
        dcos::bufferPoolAgent.Create(poolArea, sizeof poolArea, 128, "tm-pool", dcos::Visibility::Local);
    if (!pool.ok()) {
        return 0;
    }
    bool ok = true;
    const uint64_t start = readTimeStampCounter();
    for (uint32_t i = 0; i < kIterations && ok; ++i) {
        const dcos::Result<void*> block = dcos::bufferPoolAgent.Allocate(pool.value());
        ok = block.ok() && dcos::bufferPoolAgent.Return(pool.value(), block.value()) == Status::Ok;
    }
    const uint64_t elapsed = readTimeStampCounter() - start;
    (void)dcos::bufferPoolAgent.Delete(pool.value());
    return ok ? elapsed : 0;
}

struct Test {
    const char* name;
    TestFunction run;
};

constexpr Test tests[] = {
    {"basic_processing", basicProcessing},
    {"cooperative_scheduling", cooperativeScheduling},
    {"preemptive_scheduling", preemptiveScheduling},
    {"interrupt_processing", interruptProcessing},
    {"interrupt_preemption_processing", interruptPreemptionProcessing},
    {"message_processing", messageProcessing},
    {"synchronization_processing", synchronisationProcessing},
    {"memory_allocation", memoryAllocation},
};

shell::CommandResult threadMetric(shell::Shell& shell, int argc, char** argv)
{
    if (argc > 2) {
        return shell::CommandResult::UsageError;
    }
    bool ran = false;
    bool failed = false;
    for (const Test& test : tests) {
        const char* only = argc == 2 ? argv[1] : nullptr;
        if (only != nullptr) {
            const char* a = only;
            const char* b = test.name;
            while (*a != '\0' && *a == *b) {
                ++a;
                ++b;
            }
            if (*a != '\0' || *b != '\0') {
                continue;
            }
        }
        ran = true;
        const uint64_t instructions = test.run();
        if (instructions == 0) {
            shell.print("TM %s failed\r\n", test.name);
            failed = true;
            continue;
        }
        const uint64_t hundredths = instructions * 100 / kIterations;
        shell.print("TM %s iterations=%lu instructions=%llu per_iteration=%llu.%02llu\r\n", test.name,
                    static_cast<unsigned long>(kIterations), static_cast<unsigned long long>(instructions),
                    static_cast<unsigned long long>(hundredths / 100), static_cast<unsigned long long>(hundredths % 100));
    }
    if (!ran) {
        shell.print("error: no Thread-Metric test '%s'\r\n", argv[1]);
        return shell::CommandResult::Failed;
    }
    shell.print("TM done\r\n");
    return failed ? shell::CommandResult::Failed : shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND(threadMetricCommand, "threadmetric", "run the Thread-Metric benchmark suite (bench image)",
                   "threadmetric [test]", threadMetric);

} // namespace thread_metric
