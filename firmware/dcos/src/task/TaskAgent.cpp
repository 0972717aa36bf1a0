// The task agent's interface object: argument checks and id resolution in
// front of TaskManager. Every method is what a ring-3 trap will call later.
#include <dcos/GregorianCalendar.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimerManager.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos {

using internal::Scheduler;
using internal::Task;
using internal::TaskManager;

namespace {

// Killing, suspending or re-prioritising another task is allowed within the
// caller's process, or for a super user anywhere (seed 7.6).
Status checkControl(const Task& target)
{
    const Task& caller = Scheduler::current();
    if (&target == &caller || caller.superUser || caller.process == target.process) {
        return Status::Ok;
    }
    return Status::NotPermitted;
}

// The kernel's own tasks (idle, and the root task that keeps the console
// alive) share their process with the application the root task starts, so
// the process rule alone would let any application task end the console.
// Only a super user may kill or suspend them.
Status checkLifeControl(const Task& target)
{
    if (target.kernelTask && !Scheduler::current().superUser) {
        return Status::NotPermitted;
    }
    return checkControl(target);
}

} // namespace

DCOS_CONFIGURATION_SERVICE Result<ObjectId> TaskAgent::Create(const TaskAttributes& attributes, TaskEntry entry, uintptr_t argument)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    return TaskManager::create(attributes, entry, argument);
}

DCOS_CONFIGURATION_SERVICE Status TaskAgent::Delete()
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    TaskManager::exitCurrent();
}

DCOS_CONFIGURATION_SERVICE Status TaskAgent::KillTask(ObjectId id)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return task.status();
    }
    const Status allowed = checkLifeControl(*task.value());
    return allowed != Status::Ok ? allowed : TaskManager::kill(*task.value());
}

Status TaskAgent::Suspend(ObjectId id)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return task.status();
    }
    const Status allowed = checkLifeControl(*task.value());
    return allowed != Status::Ok ? allowed : TaskManager::suspend(*task.value());
}

Status TaskAgent::Resume(ObjectId id)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return task.status();
    }
    const Status allowed = checkControl(*task.value());
    return allowed != Status::Ok ? allowed : TaskManager::resume(*task.value());
}

Status TaskAgent::ChangePriority(ObjectId id, uint8_t priority)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return task.status();
    }
    const Status allowed = checkControl(*task.value());
    return allowed != Status::Ok ? allowed : TaskManager::changePriority(*task.value(), priority);
}

Status TaskAgent::SleepFor(uint64_t nanoseconds)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (nanoseconds == kWaitForever) {
        return Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    const Status status = TaskManager::blockCurrent(internal::WaitReason::Sleep, nanoseconds);
    return status == Status::Timeout ? Status::Ok : status;
}

Status TaskAgent::SleepTill(const DateTime& time)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    // A time of day, not an interval: SetSystemClock moves the wake-up with
    // the clock, as it moves day-clock alarms.
    const Result<uint64_t> target = GregorianCalendar::toNanoseconds(time);
    if (!target.ok()) {
        return target.status();
    }
    arch_x86::InterruptGuard guard;
    const Status status = TaskManager::blockCurrentTillTimeOfDay(target.value());
    return status == Status::Timeout ? Status::Ok : status;
}

Status TaskAgent::PostEvent(ObjectId id, uint32_t events)
{
    if (events == 0) {
        return Status::InvalidArgument;
    }
    return TaskManager::postEvent(id, events);
}

Result<uint32_t> TaskAgent::ReceiveEvent(uint32_t events, EventWait mode, uint64_t timeout)
{
    if (events == 0) {
        return Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    Task& task = Scheduler::current();
    const uint32_t present = task.events & events;
    if (mode == EventWait::All ? present == events : present != 0) {
        task.events &= ~present;
        return present;
    }
    if (timeout == kPoll) {
        return Status::WouldBlock;
    }
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    task.awaitedEvents = events;
    task.awaitedMode = mode;
    const Status status = TaskManager::blockCurrent(internal::WaitReason::Events, timeout);
    if (status != Status::Ok) {
        return status;
    }
    return task.receivedEvents;
}

Status TaskAgent::SendSignal(ObjectId id, unsigned signal)
{
    if (signal >= 32) {
        return Status::InvalidArgument;
    }
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return internal::orRemote(task.status(), internal::RemoteService::SendSignal, id, signal);
    }
    TaskManager::sendSignal(*task.value(), signal);
    return Status::Ok;
}

DCOS_CONFIGURATION_SERVICE Status TaskAgent::SetSignalHandler(SignalHandler handler)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    Task& task = Scheduler::current();
    task.signalHandler = handler;
    if (handler != nullptr && (task.pendingSignals & ~task.signalMask) != 0) {
        Scheduler::requestDispatch(); // Signals left pending are delivered now.
    }
    return Status::Ok;
}

Result<uint32_t> TaskAgent::SetSignalMask(uint32_t mask)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    Task& task = Scheduler::current();
    const uint32_t previous = task.signalMask;
    task.setSignalMask(mask);
    if (task.signalHandler != nullptr && (task.pendingSignals & ~mask) != 0) {
        Scheduler::requestDispatch();
    }
    return previous;
}

DCOS_CONFIGURATION_SERVICE Status TaskAgent::SetExceptionHandler(ExceptionHandler handler)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    Scheduler::current().exceptionHandler = handler;
    return Status::Ok;
}

Status TaskAgent::ThrowException(ObjectId id, ExceptionClass exceptionClass, uint32_t code)
{
    if (static_cast<uint8_t>(exceptionClass) > static_cast<uint8_t>(ExceptionClass::Fatal)) {
        return Status::InvalidArgument;
    }
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return task.status();
    }
    const Status allowed = checkControl(*task.value());
    if (allowed != Status::Ok) {
        return allowed;
    }
    if (task.value()->idle) {
        return Status::NotPermitted;
    }
    TaskManager::raiseException(*task.value(), ExceptionInfo{exceptionClass, 0xFF, code, 0, nullptr});
    return Status::Ok;
}

ObjectId TaskAgent::IdOfSelf() { return internal::currentTaskId(); }

DCOS_CONFIGURATION_SERVICE Result<ObjectId> TaskAgent::NameToObject(const char* name)
{
    return internal::orRemoteName(TaskManager::nameToObject(name), ObjectType::Task, name);
}

Result<TaskState> TaskAgent::GetState(ObjectId id)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        const Result<TaskState> remote =
            internal::remoteValueOr<TaskState>(task.status(), internal::RemoteService::TaskGetState, id);
        // Another node's answer is outside input: a state no node has is refused.
        if (remote.ok() && static_cast<uint8_t>(remote.value()) > static_cast<uint8_t>(TaskState::Terminating)) {
            return Status::Corrupted;
        }
        return remote;
    }
    arch_x86::InterruptGuard guard;
    const Task& t = *task.value();
    if (&t == &Scheduler::current()) {
        return TaskState::Executing;
    }
    return t.suspended && t.state != TaskState::Terminating ? TaskState::Suspended : t.state;
}

Result<uint8_t> TaskAgent::GetPriority(ObjectId id)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        const Result<uint32_t> remote =
            internal::remoteValueOr<uint32_t>(task.status(), internal::RemoteService::TaskGetPriority, id);
        if (!remote.ok()) {
            return remote.status();
        }
        // Another node's answer is outside input: a priority no task has is refused.
        return remote.value() > kLowestPriority ? Result<uint8_t>(Status::Corrupted)
                                                : Result<uint8_t>(static_cast<uint8_t>(remote.value()));
    }
    return task.value()->basePriority;
}

DCOS_CONFIGURATION_SERVICE Status TaskAgent::AddObjects(size_t count)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    return TaskManager::addObjects(count);
}

} // namespace dcos
