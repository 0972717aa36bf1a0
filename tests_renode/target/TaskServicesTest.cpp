// The task agent on the target: events, signals, exceptions, Suspend and
// Resume (seed 7.6).
#include "KernelTestSupport.hpp"

#include <dcos/SchedulerAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace target_test {

namespace {

using dcos::EventWait;
using dcos::ObjectId;
using dcos::Status;
using dcos::TaskState;
using dcos::taskAgent;

constexpr uint64_t kMillisecond = 1000000;

// --- Events -------------------------------------------------------------------

volatile uint32_t receivedAll = 0;
volatile uint32_t receivedAny = 0;

void allEventsEntry(uintptr_t)
{
    const dcos::Result<uint32_t> all = taskAgent.ReceiveEvent(0x3, EventWait::All, dcos::kWaitForever);
    receivedAll = all.ok() ? all.value() : 0xDEAD;
    Trace::record('L');
    const dcos::Result<uint32_t> any = taskAgent.ReceiveEvent(0xC, EventWait::Any, dcos::kWaitForever);
    receivedAny = any.ok() ? any.value() : 0xDEAD;
    Trace::record('Y');
    finished();
}

bool events(shell::Shell& shell)
{
    Trace::clear();
    const ObjectId waiter = spawn("events", 10, allEventsEntry);
    bool ok = check(shell, !waiter.isNull(), "create the waiting task");
    ok = ok && checkStatus(shell, taskAgent.PostEvent(waiter, 0x1), Status::Ok, "post event 0");
    ok = ok && check(shell, taskAgent.GetState(waiter).value() == TaskState::Blocked, "waiting for all: still blocked");
    ok = ok && checkStatus(shell, taskAgent.PostEvent(waiter, 0x2), Status::Ok, "post event 1");
    // The waiter (more urgent) ran and now waits for any of 0xC.
    ok = ok && check(shell, receivedAll == 0x3, "all: received 0x3");
    ok = ok && checkStatus(shell, taskAgent.PostEvent(waiter, 0x8 | 0x10), Status::Ok, "post events 3 and 4");
    ok = ok && waitForDone(shell, 1);
    ok = ok && check(shell, receivedAny == 0x8, "any: received only the awaited 0x8");
    ok = Trace::expect(shell, "LY") && ok;

    // Time-out, poll, and events are not queued.
    const uint64_t before = dcos::timerAgent.Uptime();
    const dcos::Result<uint32_t> timedOut = taskAgent.ReceiveEvent(0x100, EventWait::Any, 10 * kMillisecond);
    const uint64_t waited = dcos::timerAgent.Uptime() - before;
    ok = checkStatus(shell, timedOut.status(), Status::Timeout, "time-out") && ok;
    shell.print("waited %llu ns for a 10 ms time-out\r\n", static_cast<unsigned long long>(waited));
    ok = check(shell, waited >= 10 * kMillisecond && waited <= 12 * kMillisecond, "time-out of 10 ms") && ok;
    ok = checkStatus(shell, taskAgent.ReceiveEvent(0x100, EventWait::Any, dcos::kPoll).status(), Status::WouldBlock,
                     "poll") && ok;
    const ObjectId self = taskAgent.IdOfSelf();
    (void)taskAgent.PostEvent(self, 0x200);
    (void)taskAgent.PostEvent(self, 0x200);
    ok = check(shell, taskAgent.ReceiveEvent(0x200, EventWait::Any, dcos::kPoll).value() == 0x200, "first receive") && ok;
    ok = checkStatus(shell, taskAgent.ReceiveEvent(0x200, EventWait::Any, dcos::kPoll).status(), Status::WouldBlock,
                     "a second post of the same event is not queued") && ok;
    ok = checkStatus(shell, taskAgent.ReceiveEvent(0, EventWait::Any, dcos::kPoll).status(), Status::InvalidArgument,
                     "empty event set") && ok;
    return ok;
}

DCOS_TARGET_TEST(eventsTest, "events", "event flags: all, any, time-out, poll, not queued", events);

// --- Signals ----------------------------------------------------------------------

ObjectId signalTask;

void signalHandler(unsigned signal)
{
    Trace::record('<');
    Trace::record(static_cast<char>('0' + signal));
    if (signal == 1) {
        // A more urgent signal sent during a handler waits for it to end.
        (void)taskAgent.SendSignal(signalTask, 0);
        Trace::record('|');
    }
    Trace::record('>');
}

void signalledEntry(uintptr_t)
{
    (void)taskAgent.SetSignalHandler(signalHandler);
    (void)taskAgent.SetSignalMask(1u << 3);
    (void)taskAgent.ReceiveEvent(1, EventWait::Any, dcos::kWaitForever);
    Trace::record('W'); // Woken; signals 1 and 5 were delivered first.
    (void)taskAgent.SetSignalMask(0); // Unmasking delivers the held signal 3.
    Trace::record('U');
    finished();
}

bool signals(shell::Shell& shell)
{
    Trace::clear();
    signalTask = spawn("signals", 10, signalledEntry);
    bool ok = check(shell, !signalTask.isNull(), "create the signalled task");
    // It waits for an event; signals do not wake it.
    ok = ok && checkStatus(shell, taskAgent.SendSignal(signalTask, 5), Status::Ok, "signal 5");
    ok = ok && checkStatus(shell, taskAgent.SendSignal(signalTask, 3), Status::Ok, "signal 3 (masked)");
    ok = ok && checkStatus(shell, taskAgent.SendSignal(signalTask, 1), Status::Ok, "signal 1");
    ok = ok && check(shell, taskAgent.GetState(signalTask).value() == TaskState::Blocked, "signals do not wake");
    ok = ok && checkStatus(shell, taskAgent.SendSignal(signalTask, 32), Status::InvalidArgument, "signal 32");
    (void)taskAgent.PostEvent(signalTask, 1);
    ok = ok && waitForDone(shell, 1);
    // Priority order 1 before 5, signal 0 not nested inside 1's handler,
    // 3 held until unmasked.
    return Trace::expect(shell, "<1|><0><5>W<3>U") && ok;
}

DCOS_TARGET_TEST(signalsTest, "signals", "signals: priority order, no nesting, masking", signals);

// --- Suspend and Resume -----------------------------------------------------------

volatile uint32_t spinCounter = 0;

void counterEntry(uintptr_t)
{
    for (;;) {
        spinCounter = spinCounter + 1;
    }
}

bool suspendResume(shell::Shell& shell)
{
    spinCounter = 0;
    const ObjectId counter = spawn("counter", 30, counterEntry); // Runs when the test task sleeps.
    bool ok = check(shell, !counter.isNull(), "create the counting task");
    (void)taskAgent.SleepFor(5 * kMillisecond);
    const uint32_t running = spinCounter;
    ok = ok && check(shell, running > 0, "the counter runs while the test task sleeps");
    ok = ok && checkStatus(shell, taskAgent.Suspend(counter), Status::Ok, "Suspend");
    ok = ok && check(shell, taskAgent.GetState(counter).value() == TaskState::Suspended, "state Suspended");
    const uint32_t atSuspend = spinCounter;
    (void)taskAgent.SleepFor(5 * kMillisecond);
    ok = ok && check(shell, spinCounter == atSuspend, "a suspended task does not run");
    ok = ok && checkStatus(shell, taskAgent.Resume(counter), Status::Ok, "Resume");
    (void)taskAgent.SleepFor(5 * kMillisecond);
    ok = ok && check(shell, spinCounter > atSuspend, "a resumed task runs again");
    ok = ok && checkStatus(shell, taskAgent.Resume(counter), Status::InvalidArgument, "Resume of a running task");
    shell.print("counter: %lu before suspend, %lu after resume\r\n", static_cast<unsigned long>(atSuspend),
                static_cast<unsigned long>(spinCounter));
    ok = checkStatus(shell, taskAgent.KillTask(counter), Status::Ok, "KillTask") && ok;
    return ok;
}

DCOS_TARGET_TEST(suspendResumeTest, "suspend", "Suspend stops a task, Resume restarts it", suspendResume);

// --- Exceptions --------------------------------------------------------------------

volatile uint8_t seenVector = 0xEE;
volatile uint8_t seenClass = 0xEE;

void recovered()
{
    Trace::record('R');
    finished();
}

dcos::ExceptionAction recoverFromDivideError(dcos::ExceptionInfo& info)
{
    seenVector = info.vector;
    seenClass = static_cast<uint8_t>(info.exceptionClass);
    Trace::record('X');
    info.resumeIn = recovered;
    return dcos::ExceptionAction::Continue;
}

void divideEntry(uintptr_t withHandler)
{
    if (withHandler != 0) {
        (void)taskAgent.SetExceptionHandler(recoverFromDivideError);
    }
    Trace::record('D');
    asm volatile("xorl %%ecx, %%ecx\n\tdivl %%ecx" ::: "eax", "ecx", "edx", "memory", "cc");
    Trace::record('!'); // Not reached: the divide faults.
    finished();
}

dcos::ExceptionAction continueAfterThrow(dcos::ExceptionInfo& info)
{
    Trace::record(info.exceptionClass == dcos::ExceptionClass::Asynchronous ? 'A' : '?');
    Trace::record(static_cast<char>('0' + info.errorCode));
    return dcos::ExceptionAction::Continue;
}

void throwTargetEntry(uintptr_t)
{
    (void)taskAgent.SetExceptionHandler(continueAfterThrow);
    (void)taskAgent.ReceiveEvent(1, EventWait::Any, dcos::kWaitForever);
    Trace::record('C'); // Continued after the handler.
    finished();
}

bool exceptions(shell::Shell& shell)
{
    // A handler catches the divide error and the task continues in its
    // recovery function.
    Trace::clear();
    bool ok = check(shell, !spawn("divide", 10, divideEntry, 1).isNull(), "create the dividing task");
    ok = ok && waitForDone(shell, 1);
    ok = Trace::expect(shell, "DXR") && ok;
    ok = check(shell, seenVector == 0 && seenClass == static_cast<uint8_t>(dcos::ExceptionClass::Synchronous),
               "the handler saw vector 0, class synchronous") && ok;

    // Without a handler the task ends and the node carries on.
    Trace::clear();
    const ObjectId unguarded = spawn("unguarded", 10, divideEntry, 0);
    ok = check(shell, !unguarded.isNull(), "create the unguarded task") && ok;
    ok = check(shell, !taskAgent.GetState(unguarded).ok(), "the unguarded task is gone") && ok;
    ok = Trace::expect(shell, "D") && ok;

    // An exception thrown by another task reaches the handler; the task continues.
    Trace::clear();
    const ObjectId target = spawn("throw-target", 10, throwTargetEntry);
    ok = check(shell, !target.isNull(), "create the throw target") && ok;
    ok = checkStatus(shell, taskAgent.ThrowException(target, dcos::ExceptionClass::Asynchronous, 7), Status::Ok,
                     "ThrowException") && ok;
    (void)taskAgent.PostEvent(target, 1);
    ok = ok && waitForDone(shell, 1);
    ok = Trace::expect(shell, "A7C") && ok;
    return ok;
}

DCOS_TARGET_TEST(exceptionsTest, "exceptions", "exceptions: handler recovers a divide error, thrown exceptions",
                 exceptions);

} // namespace

} // namespace target_test
