// The scheduler agent on the target: preemption from interrupts with the
// dispatch deferred to the outermost exit, round robin, time slicing,
// priorities and deadline scheduling (seed 7.3.3, 7.4).
#include "SpareLine.hpp"
#include "KernelTestSupport.hpp"

#include <dcos/SchedulerAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/TimerManager.hpp>

#include <arch_x86/Cpu.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::schedulerAgent;
using dcos::systemAgent;
using dcos::taskAgent;

constexpr uint64_t kMillisecond = 1000000;

// --- Preemption from a nested interrupt ------------------------------------

// The node's two spare lines; the test raises their vectors by software.
unsigned outerLine() { return target_test::spareLine(0); }
unsigned innerLine() { return target_test::spareLine(1); }
ObjectId urgentTask;

void innerIsr(void*)
{
    Trace::record('i');
    (void)taskAgent.PostEvent(urgentTask, 1);
    Trace::record('I');
}

void outerIsr(void*)
{
    Trace::record('o');
    target_test::raiseSpareLine(1); // Nest: the inner line's vector.
    Trace::record('O');
}

void urgentEntry(uintptr_t)
{
    (void)taskAgent.ReceiveEvent(1, dcos::EventWait::Any, dcos::kWaitForever);
    Trace::record('H');
    finished();
}

bool preemptionFromInterrupt(shell::Shell& shell)
{
    Trace::clear();
    urgentTask = spawn("urgent", 2, urgentEntry);
    bool ok = check(shell, !urgentTask.isNull(), "create the urgent task");
    ok = ok && checkStatus(shell, systemAgent.InstallISR(outerLine(), outerIsr, nullptr), Status::Ok, "InstallISR outer");
    ok = ok && checkStatus(shell, systemAgent.InstallISR(innerLine(), innerIsr, nullptr), Status::Ok, "InstallISR inner");
    // The urgent task has run up to its wait. Now: test task 's', outer
    // handler, nested inner handler readying the urgent task, back out.
    Trace::record('s');
    target_test::raiseSpareLine(0); // The outer line's vector.
    Trace::record('S');
    ok = ok && waitForDone(shell, 1);
    (void)systemAgent.RemoveISR(outerLine());
    (void)systemAgent.RemoveISR(innerLine());
    // The urgent task runs after the outer handler ends ('O'), before the
    // interrupted test task continues ('S'), and not at the inner exit.
    return Trace::expect(shell, "soiIOHS") && ok;
}

DCOS_TARGET_TEST(preemptionTest, "preempt", "a task readied in a nested ISR runs at the outermost exit",
                 preemptionFromInterrupt);

// --- Round robin -------------------------------------------------------------

void yieldingEntry(uintptr_t mark)
{
    for (int i = 0; i < 3; ++i) {
        Trace::record(static_cast<char>(mark));
        // Whichever path resumed the task, Yield reports Ok.
        if (schedulerAgent.Yield() != Status::Ok) {
            Trace::record('!');
        }
    }
    finished();
}

bool roundRobin(shell::Shell& shell)
{
    Trace::clear();
    HoldScheduling hold;
    bool ok = !spawn("rr-a", 10, yieldingEntry, 'A').isNull();
    ok = ok && !spawn("rr-b", 10, yieldingEntry, 'B').isNull();
    ok = ok && !spawn("rr-c", 10, yieldingEntry, 'C').isNull();
    hold.release();
    ok = check(shell, ok, "create three tasks") && waitForDone(shell, 3);
    return Trace::expect(shell, "ABCABCABC") && ok;
}

DCOS_TARGET_TEST(roundRobinTest, "roundrobin", "Yield passes the CPU among equal priorities", roundRobin);

// --- Yield's general cases ---------------------------------------------------------
//
// Yield's fast path (scheduler/TaskContextSwitch.S) takes only a next task that
// left through a direct switch and has nothing to be delivered. These two
// cases must go the general way: a next task preempted at an interrupt's
// exit, which resumes from its interrupt frame, and a next task with a
// signal pending, whose handler runs before it continues.

volatile bool yieldPhase = false;

// Spins, time-sliced, until the yielding partner has seen it run; it can
// only have lost the CPU at a tick, so it is parked with an interrupt frame.
void preemptedPartnerEntry(uintptr_t)
{
    Trace::record('b');
    while (!yieldPhase) {
    }
    Trace::record('B');
    finished();
}

void yieldToPreemptedEntry(uintptr_t)
{
    Trace::record('a');
    for (;;) {
        const char* text = Trace::text();
        if (text[0] != '\0' && text[1] == 'b') {
            break; // The partner ran, and the tick that ended its slice gave the CPU back.
        }
    }
    yieldPhase = true;
    if (schedulerAgent.Yield() != Status::Ok) {
        Trace::record('!');
    }
    Trace::record('A');
    finished();
}

void yieldSignalHandler(unsigned) { Trace::record('h'); }

void signalledPartnerEntry(uintptr_t)
{
    (void)taskAgent.SetSignalHandler(yieldSignalHandler);
    Trace::record('b');
    if (schedulerAgent.Yield() != Status::Ok) { // Parked by the fast path.
        Trace::record('!');
    }
    Trace::record('B');
    finished();
}

ObjectId signalledPartner;

void yieldToSignalledEntry(uintptr_t)
{
    Trace::record('a');
    (void)schedulerAgent.Yield(); // The partner runs and installs its handler.
    (void)taskAgent.SendSignal(signalledPartner, 4);
    if (schedulerAgent.Yield() != Status::Ok) { // Its handler runs before it continues.
        Trace::record('!');
    }
    Trace::record('A');
    finished();
}

bool yieldGeneralCases(shell::Shell& shell)
{
    bool ok = checkStatus(shell, schedulerAgent.SetTimeSliceQuantum(2 * kMillisecond), Status::Ok, "quantum 2 ms");
    Trace::clear();
    yieldPhase = false;
    {
        HoldScheduling hold;
        ok = ok && !spawn("yield-a", 10, yieldToPreemptedEntry, 0, true).isNull();
        ok = ok && !spawn("yield-b", 10, preemptedPartnerEntry, 0, true).isNull();
    }
    ok = ok && waitForDone(shell, 2);
    ok = Trace::expect(shell, "abBA") && ok;
    (void)schedulerAgent.SetTimeSliceQuantum(10 * kMillisecond);

    Trace::clear();
    {
        HoldScheduling hold;
        ok = ok && !spawn("yield-c", 10, yieldToSignalledEntry).isNull();
        signalledPartner = spawn("yield-d", 10, signalledPartnerEntry);
        ok = ok && !signalledPartner.isNull();
    }
    ok = ok && waitForDone(shell, 2);
    return Trace::expect(shell, "abhBA") && ok;
}

DCOS_TARGET_TEST(yieldGeneralCasesTest, "yieldcases",
                 "Yield resumes a partner preempted at a tick and delivers a partner's pending signal",
                 yieldGeneralCases);

// --- Time slicing --------------------------------------------------------------

volatile bool slicingStop = false;

// Records its mark each time it gets the CPU back from another task.
void slicedEntry(uintptr_t mark)
{
    const uint64_t end = dcos::timerAgent.Uptime() + 60 * kMillisecond;
    while (dcos::timerAgent.Uptime() < end) {
        const char* text = Trace::text();
        size_t length = 0;
        while (text[length] != '\0') {
            ++length;
        }
        if (length == 0 || text[length - 1] != static_cast<char>(mark)) {
            Trace::record(static_cast<char>(mark));
        }
    }
    finished();
}

bool timeSlicing(shell::Shell& shell)
{
    bool ok = checkStatus(shell, schedulerAgent.SetTimeSliceQuantum(5 * kMillisecond), Status::Ok, "quantum 5 ms");
    // Time-sliced: two equal tasks that never yield still alternate.
    Trace::clear();
    {
        HoldScheduling hold;
        ok = ok && !spawn("slice-a", 10, slicedEntry, 'A', true).isNull();
        ok = ok && !spawn("slice-b", 10, slicedEntry, 'B', true).isNull();
    }
    ok = ok && waitForDone(shell, 2);
    const char* sliced = Trace::text();
    size_t switches = 0;
    while (sliced[switches] != '\0') {
        ++switches;
    }
    shell.print("time-sliced trace \"%s\" (%u turns in 2 x 60 ms at 5 ms quanta)\r\n", sliced,
                static_cast<unsigned>(switches));
    // About 24 turns; at least 10 shows slicing, a lone "AB" shows none.
    ok = check(shell, switches >= 10, "time-sliced tasks alternate") && ok;

    // Not time-sliced: the first runs to completion before the second.
    Trace::clear();
    {
        HoldScheduling hold;
        ok = ok && !spawn("plain-a", 10, slicedEntry, 'A', false).isNull();
        ok = ok && !spawn("plain-b", 10, slicedEntry, 'B', false).isNull();
    }
    ok = ok && waitForDone(shell, 2);
    ok = Trace::expect(shell, "AB") && ok;
    (void)schedulerAgent.SetTimeSliceQuantum(10 * kMillisecond);
    ok = checkStatus(shell, schedulerAgent.SetTimeSliceQuantum(1000), Status::InvalidArgument, "quantum below a tick") && ok;
    return ok;
}

DCOS_TARGET_TEST(timeSlicingTest, "timeslice", "time-sliced equal tasks alternate without yielding", timeSlicing);

// --- Priorities ------------------------------------------------------------------

void markEntry(uintptr_t mark)
{
    Trace::record(static_cast<char>(mark));
    finished();
}

bool changePriority(shell::Shell& shell)
{
    Trace::clear();
    ObjectId a, b;
    bool ok;
    {
        HoldScheduling hold;
        a = spawn("prio-a", 20, markEntry, 'A');
        b = spawn("prio-b", 21, markEntry, 'B');
        ok = check(shell, !a.isNull() && !b.isNull(), "create two tasks");
        ok = ok && checkStatus(shell, taskAgent.ChangePriority(b, 19), Status::Ok, "ChangePriority");
        ok = ok && check(shell, taskAgent.GetPriority(b).value() == 19, "GetPriority shows the change");
        ok = ok && checkStatus(shell, taskAgent.ChangePriority(b, 32), Status::InvalidArgument, "priority 32");
    }
    ok = ok && waitForDone(shell, 2);
    return Trace::expect(shell, "BA") && ok;
}

DCOS_TARGET_TEST(changePriorityTest, "priority", "ChangePriority reorders ready tasks", changePriority);

// --- Deadline scheduling ---------------------------------------------------------

struct DeadlineSpec {
    char mark;
    uint64_t executionNs;
    uint64_t deadlineNs;
};

constexpr uint32_t kStartEvent = 1;

void deadlineEntry(uintptr_t argument)
{
    const DeadlineSpec& spec = *reinterpret_cast<const DeadlineSpec*>(argument);
    // "Set later": the scope starts when the start event readies the task,
    // so every task's arrival is the same instant.
    (void)schedulerAgent.SetDeadline(dcos::DeadlineStart::AtNextBlock, spec.executionNs, spec.deadlineNs);
    (void)taskAgent.ReceiveEvent(kStartEvent, dcos::EventWait::Any, dcos::kWaitForever);
    Trace::record(spec.mark);
    (void)schedulerAgent.ClearDeadline();
    finished();
}

void waitThenMarkEntry(uintptr_t mark)
{
    (void)taskAgent.ReceiveEvent(kStartEvent, dcos::EventWait::Any, dcos::kWaitForever);
    Trace::record(static_cast<char>(mark));
    finished();
}

// Latest start time = arrival + deadline - execution:
//   b: 20 - 1 = 19 ms; '2': 25 - 5 = 20 ms; '1': 30 - 10 = 20 ms (tie with
//   '2', broken by the shorter deadline period); a: 50 - 1 = 49 ms.
constexpr DeadlineSpec deadlineSpecs[] = {
    {'a', 1 * kMillisecond, 50 * kMillisecond},
    {'1', 10 * kMillisecond, 30 * kMillisecond},
    {'b', 1 * kMillisecond, 20 * kMillisecond},
    {'2', 5 * kMillisecond, 25 * kMillisecond},
};

bool deadlineOrdering(shell::Shell& shell)
{
    Trace::clear();
    ObjectId ids[5];
    bool ok = true;
    {
        HoldScheduling hold;
        for (unsigned i = 0; i < 4; ++i) {
            ids[i] = spawn("deadline", 10, deadlineEntry, reinterpret_cast<uintptr_t>(&deadlineSpecs[i]));
            ok = ok && !ids[i].isNull();
        }
        // A static task more urgent by priority still runs after every task
        // in a deadline scope (seed 7.4.1).
        ids[4] = spawn("static", 5, waitThenMarkEntry, 'S');
        ok = check(shell, ok && !ids[4].isNull(), "create five tasks");
        hold.release();
    }
    // All five now wait. Start them at one instant: with interrupts off no
    // tick passes between the posts, and a scope of its own at priority 0
    // (the most urgent key) keeps the test task running until every post is
    // made, since tasks in a scope would otherwise preempt it at once.
    {
        HoldScheduling holdAgain;
        ok = ok && checkStatus(shell, schedulerAgent.SetDeadline(dcos::DeadlineStart::Now, 0, kMillisecond),
                               Status::Ok, "test task enters a scope");
        {
            arch_x86::InterruptGuard guard;
            for (const ObjectId& id : ids) {
                (void)taskAgent.PostEvent(id, kStartEvent);
            }
        }
        (void)schedulerAgent.ClearDeadline();
    }
    ok = ok && waitForDone(shell, 5);
    return Trace::expect(shell, "b21aS") && ok;
}

DCOS_TARGET_TEST(deadlineOrderingTest, "deadline", "deadline tasks run by latest start time, with tie-breaks",
                 deadlineOrdering);

volatile uint64_t timingExceptionAt = 0;
volatile uint64_t missedDeadlineAt = 0;

dcos::ExceptionAction recordTimingException(dcos::ExceptionInfo& info)
{
    if (info.exceptionClass == dcos::ExceptionClass::Timing) {
        timingExceptionAt = dcos::timerAgent.Uptime();
        Trace::record('T');
    }
    return dcos::ExceptionAction::Continue;
}

void lateEntry(uintptr_t withHandler)
{
    if (withHandler != 0) {
        (void)taskAgent.SetExceptionHandler(recordTimingException);
    }
    missedDeadlineAt = dcos::timerAgent.Uptime() + 5 * kMillisecond;
    (void)schedulerAgent.SetDeadline(dcos::DeadlineStart::Now, 1 * kMillisecond, 5 * kMillisecond);
    spin(20 * kMillisecond); // Overrun the deadline.
    (void)schedulerAgent.ClearDeadline();
    Trace::record('E');
    finished();
}

bool missedDeadline(shell::Shell& shell)
{
    Trace::clear();
    timingExceptionAt = 0;
    bool ok = check(shell, !spawn("late", 10, lateEntry, 1).isNull(), "create the late task");
    ok = ok && waitForDone(shell, 1);
    ok = Trace::expect(shell, "TE") && ok;
    const uint64_t delay = timingExceptionAt - missedDeadlineAt;
    shell.print("timing exception %llu ns after the deadline\r\n", static_cast<unsigned long long>(delay));
    // Within one tick of the deadline (and the few microseconds of kernel
    // work between the expiring tick and the handler reading the clock).
    ok = check(shell, timingExceptionAt >= missedDeadlineAt &&
                          delay <= dcos::internal::TimerManager::tickPeriodNs() + 50000,
               "timing exception within one tick of the deadline") && ok;

    // Without a handler the timing exception is ignored: the task finishes.
    Trace::clear();
    ok = ok && check(shell, !spawn("late-quiet", 10, lateEntry, 0).isNull(), "create the second late task");
    ok = ok && waitForDone(shell, 1);
    ok = Trace::expect(shell, "E") && ok;
    ok = checkStatus(shell, schedulerAgent.ClearDeadline(), Status::InvalidArgument, "ClearDeadline outside a scope") && ok;
    ok = checkStatus(shell, schedulerAgent.SetDeadline(dcos::DeadlineStart::Now, 10, 5), Status::InvalidArgument,
                     "execution period longer than the deadline") && ok;
    return ok;
}

DCOS_TARGET_TEST(missedDeadlineTest, "deadlinemiss", "a missed deadline raises a timing exception within a tick",
                 missedDeadline);

} // namespace

} // namespace target_test
