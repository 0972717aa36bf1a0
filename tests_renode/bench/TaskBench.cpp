// Benchmarks of the task agent's primitives (seed 7.6, Table 9.5).
//
// The object count is the number of tasks in the system. Unless a benchmark
// says otherwise the tasks besides the shell are fillers blocked for ever on
// an event no one posts, and the measured call acts on the newest of them,
// "target". Primitives that act on the caller act on the shell task that
// runs the benchmarks. Task.AddObjects is in ConfigurationBench.cpp.
#include "BenchSupport.hpp"

#include <dcos/GregorianCalendar.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace bench {
namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::taskAgent;

constexpr uint64_t kMillisecond = 1000000;

ObjectId target;
ObjectId partner;
volatile uint32_t lastValue;

constexpr uint32_t kSelfEvent = 1u << 2;

void clearAll()
{
    killTasks();
    // Leave no event of ours pending for the shell (bit 0 is the console's).
    (void)taskAgent.ReceiveEvent(kSelfEvent, dcos::EventWait::Any, dcos::kPoll);
    target = ObjectId::null();
    partner = ObjectId::null();
}

Status populate(uint32_t tasks)
{
    return fillTasks(tasks, kBlockedFillerPriority, &target);
}

// --- Task.Create (variable in the seed: the stack is allocated): one more
// task, of lower priority than the shell so it does not run; killed again.

ObjectId created;

Status populateButOne(uint32_t tasks) { return fillTasks(tasks - 1, kBlockedFillerPriority, &target); }

void createTask()
{
    dcos::TaskAttributes attributes;
    attributes.priority = kReadyFillerPriority;
    attributes.stackSize = dcos::kMinimumStackSize;
    const Result<ObjectId> id = taskAgent.Create(attributes, blockForever, 0);
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void killCreated()
{
    (void)taskAgent.KillTask(created);
    created = ObjectId::null();
}

// --- Task.Delete (variable in the seed): a task ends itself. Self-timed
// from the victim's Delete call to the shell's first instruction after it
// (the victim, woken by the shell's PostEvent, runs first at priority 20).

constexpr uint32_t kVictimEvent = 1u << 0;

void deleteWhenWoken(uintptr_t)
{
    (void)taskAgent.ReceiveEvent(kVictimEvent, dcos::EventWait::Any, dcos::kWaitForever);
    markStart();
    (void)taskAgent.Delete();
}

Status spawnDeletingVictim()
{
    const Result<ObjectId> id = spawnTask(deleteWhenWoken, kBlockedFillerPriority);
    partner = id.ok() ? id.value() : ObjectId::null();
    return id.status();
}

Status populateWithDeletingVictim(uint32_t tasks)
{
    const Status status = fillTasks(tasks - 1, kBlockedFillerPriority, &target);
    return status != Status::Ok ? status : spawnDeletingVictim();
}

void wakeVictimToDelete()
{
    (void)taskAgent.PostEvent(partner, kVictimEvent);
    markEnd();
}

void replaceDeletedVictim()
{
    forgetTask(partner);
    (void)spawnDeletingVictim();
}

// --- Task.KillTask: one blocked task killed by the shell; a new one takes its place.

Status spawnBlockedVictim()
{
    const Result<ObjectId> id = spawnTask(blockForever, kBlockedFillerPriority);
    partner = id.ok() ? id.value() : ObjectId::null();
    return id.status();
}

Status populateWithBlockedVictim(uint32_t tasks)
{
    const Status status = fillTasks(tasks - 1, kBlockedFillerPriority, &target);
    return status != Status::Ok ? status : spawnBlockedVictim();
}

void killVictim() { check(taskAgent.KillTask(partner)); }

void replaceKilledVictim()
{
    forgetTask(partner);
    (void)spawnBlockedVictim();
}

// --- Task.Suspend and Task.Resume of the blocked target.

void suspendTarget() { check(taskAgent.Suspend(target)); }
void resumeTarget() { check(taskAgent.Resume(target)); }

Status populateSuspended(uint32_t tasks)
{
    const Status status = populate(tasks);
    return status != Status::Ok ? status : taskAgent.Suspend(target);
}

// --- Task.ChangePriority of the blocked target, and back (unmeasured).

void raiseTargetPriority() { check(taskAgent.ChangePriority(target, kBlockedFillerPriority - 1)); }
void restoreTargetPriority() { (void)taskAgent.ChangePriority(target, kBlockedFillerPriority); }

// --- Task.SleepFor and Task.SleepTill ("overhead only" in the seed):
// self-timed from the shell's call to the first instruction of the task
// that runs instead, a partner below the shell's priority, which then waits
// for an event the restore step posts. The sleep itself is not counted.

constexpr uint32_t kPartnerEvent = 1u << 1;

void markThenWait(uintptr_t)
{
    for (;;) {
        markEnd();
        (void)taskAgent.ReceiveEvent(kPartnerEvent, dcos::EventWait::Any, dcos::kWaitForever);
    }
}

Status populateWithWaitingPartner(uint32_t tasks)
{
    const Result<ObjectId> id = spawnTask(markThenWait, static_cast<uint8_t>(selfPriority() + 1));
    if (!id.ok()) {
        return id.status();
    }
    partner = id.value();
    return populate(tasks);
}

void readyPartner() { (void)taskAgent.PostEvent(partner, kPartnerEvent); }

void sleepForOneMillisecond()
{
    markStart();
    (void)taskAgent.SleepFor(kMillisecond);
}

dcos::DateTime wakeTime;

void chooseWakeTime()
{
    wakeTime = dcos::GregorianCalendar::fromNanoseconds(dcos::internal::TimerManager::timeOfDayNs() + 2 * kMillisecond);
}

Status populateForSleepTill(uint32_t tasks)
{
    chooseWakeTime();
    return populateWithWaitingPartner(tasks);
}

void readyPartnerAndChooseWakeTime()
{
    readyPartner();
    chooseWakeTime();
}

void sleepTill()
{
    markStart();
    (void)taskAgent.SleepTill(wakeTime);
}

// --- Task.PostEvent to the blocked target, an event it does not wait for
// (waking a task is Kernel.StaticScheduling).

void postEventToTarget() { check(taskAgent.PostEvent(target, kPartnerEvent)); }

// --- Task.PendOnEvents (ReceiveEvent, "available/polling" in the seed):
// the event is already there.

Status populateWithOwnEvent(uint32_t tasks)
{
    const Status status = populate(tasks);
    return status != Status::Ok ? status : taskAgent.PostEvent(self(), kSelfEvent);
}

void receiveAvailableEvent()
{
    const Result<uint32_t> events = taskAgent.ReceiveEvent(kSelfEvent, dcos::EventWait::Any, dcos::kPoll);
    check(events.status());
    lastValue = events.ok() ? events.value() : 0;
}

void postOwnEvent() { (void)taskAgent.PostEvent(self(), kSelfEvent); }

// --- Task.ReceiveEvent: the event is not there, so the shell blocks.
// Self-timed from the call to the first instruction of the partner (below
// the shell's priority) that runs instead; the partner then posts the event.

void markThenPostToShell(uintptr_t shell)
{
    for (;;) {
        markEnd();
        (void)taskAgent.PostEvent(ObjectId::fromRaw(static_cast<uint32_t>(shell)), kSelfEvent);
    }
}

Status populateWithPostingPartner(uint32_t tasks)
{
    const Result<ObjectId> id =
        spawnTask(markThenPostToShell, static_cast<uint8_t>(selfPriority() + 1), self().raw());
    if (!id.ok()) {
        return id.status();
    }
    partner = id.value();
    return populate(tasks);
}

void receiveEventBlocking()
{
    markStart();
    (void)taskAgent.ReceiveEvent(kSelfEvent, dcos::EventWait::Any, dcos::kWaitForever);
}

// --- Task.SendSignal to the blocked target (held pending: it has no handler).

void sendSignalToTarget() { check(taskAgent.SendSignal(target, 5)); }

// --- Task.SetSignalHandler, SetSignalMask, SetExceptionHandler: the shell's own.

void ignoreSignal(unsigned) {}

dcos::ExceptionAction ignoreException(dcos::ExceptionInfo&) { return dcos::ExceptionAction::Continue; }

void setSignalHandler() { check(taskAgent.SetSignalHandler(ignoreSignal)); }

void clearHandlers()
{
    (void)taskAgent.SetSignalHandler(nullptr);
    (void)taskAgent.SetExceptionHandler(nullptr);
    (void)taskAgent.SetSignalMask(0);
    clearAll();
}

void setSignalMask()
{
    const Result<uint32_t> previous = taskAgent.SetSignalMask(1u << 5);
    check(previous.status());
    lastValue = previous.ok() ? previous.value() : 0;
}

void setExceptionHandler() { check(taskAgent.SetExceptionHandler(ignoreException)); }

// --- Task.ThrowException: an asynchronous exception marked for the blocked
// target (delivered when it next runs, which it never does).

void throwExceptionAtTarget() { check(taskAgent.ThrowException(target, dcos::ExceptionClass::Asynchronous, 7)); }

// --- Task.IdOfSelf.

volatile uint32_t selfId;

void idOfSelf() { selfId = taskAgent.IdOfSelf().raw(); }

// --- Task.NameToObject (configuration): the newest task, "target".

void nameToObject()
{
    const Result<ObjectId> id = taskAgent.NameToObject("target");
    check(id.status());
    lastValue = id.ok() ? id.value().raw() : 0;
}

} // namespace

DCOS_BENCHMARK(taskCreateBench, "Task.Create", populateButOne, createTask, Cost::Variable, .restore = killCreated,
               .teardown = clearAll);
DCOS_BENCHMARK(taskDeleteBench, "Task.Delete", populateWithDeletingVictim, wakeVictimToDelete, Cost::Variable,
               .restore = replaceDeletedVictim, .teardown = clearAll, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(taskKillTaskBench, "Task.KillTask", populateWithBlockedVictim, killVictim, Cost::Constant,
               .restore = replaceKilledVictim, .teardown = clearAll);
DCOS_BENCHMARK(taskSuspendBench, "Task.Suspend", populate, suspendTarget, Cost::Constant, .restore = resumeTarget,
               .teardown = clearAll);
DCOS_BENCHMARK(taskResumeBench, "Task.Resume", populateSuspended, resumeTarget, Cost::Constant,
               .restore = suspendTarget, .teardown = clearAll);
DCOS_BENCHMARK(taskChangePriorityBench, "Task.ChangePriority", populate, raiseTargetPriority, Cost::Constant,
               .restore = restoreTargetPriority, .teardown = clearAll);
DCOS_BENCHMARK(taskSleepForBench, "Task.SleepFor", populateWithWaitingPartner, sleepForOneMillisecond,
               Cost::Constant, .restore = readyPartner, .teardown = clearAll, .interruptsEnabled = true,
               .selfTimed = true);
DCOS_BENCHMARK(taskSleepTillBench, "Task.SleepTill", populateForSleepTill, sleepTill, Cost::Constant,
               .restore = readyPartnerAndChooseWakeTime, .teardown = clearAll, .interruptsEnabled = true,
               .selfTimed = true);
DCOS_BENCHMARK(taskPostEventBench, "Task.PostEvent", populate, postEventToTarget, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(taskPendOnEventsBench, "Task.PendOnEvents", populateWithOwnEvent, receiveAvailableEvent,
               Cost::Constant, .restore = postOwnEvent, .teardown = clearAll);
DCOS_BENCHMARK(taskReceiveEventBench, "Task.ReceiveEvent", populateWithPostingPartner, receiveEventBlocking,
               Cost::Constant, .teardown = clearAll, .interruptsEnabled = true, .selfTimed = true);
DCOS_BENCHMARK(taskSendSignalBench, "Task.SendSignal", populate, sendSignalToTarget, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(taskSetSignalHandlerBench, "Task.SetSignalHandler", populate, setSignalHandler, Cost::Constant,
               .teardown = clearHandlers);
DCOS_BENCHMARK(taskSetSignalMaskBench, "Task.SetSignalMask", populate, setSignalMask, Cost::Constant,
               .teardown = clearHandlers);
DCOS_BENCHMARK(taskThrowExceptionBench, "Task.ThrowException", populate, throwExceptionAtTarget, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(taskSetExceptionHandlerBench, "Task.SetExceptionHandler", populate, setExceptionHandler,
               Cost::Constant, .teardown = clearHandlers);
DCOS_BENCHMARK(taskIdOfSelfBench, "Task.IdOfSelf", populate, idOfSelf, Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(taskNameToObjectBench, "Task.NameToObject", populate, nameToObject, Cost::Variable,
               .teardown = clearAll);

} // namespace bench
