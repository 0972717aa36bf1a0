// The scheduler agent's interface object (seed 7.4).
#include <dcos/SchedulerAgent.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimerManager.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos {

using internal::Scheduler;
using internal::Task;
using internal::TaskManager;
using internal::TimerManager;

// SchedulerAgent::Yield is scheduler/TaskContextSwitch.S, which handles the
// common case itself and jumps here for every other one.
extern "C" Status dcosYieldGeneral()
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    Scheduler::yieldCurrent();
    return Status::Ok;
}

Status SchedulerAgent::SetDeadline(DeadlineStart start, uint64_t executionPeriodNs, uint64_t deadlinePeriodNs)
{
    if (deadlinePeriodNs == 0 || executionPeriodNs > deadlinePeriodNs ||
        static_cast<uint8_t>(start) > static_cast<uint8_t>(DeadlineStart::AtNextBlock)) {
        return Status::InvalidArgument;
    }
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    Task& task = Scheduler::current();
    // A new deadline replaces the current scope.
    Scheduler::makeUnready(task);
    TimerManager::cancel(task.deadlineTimeout);
    task.executionPeriodNs = executionPeriodNs;
    task.deadlinePeriodNs = deadlinePeriodNs;
    if (start == DeadlineStart::Now) {
        task.deadlineAtNextBlock = false;
        task.setDeadlineScope(true);
        task.deadlineNs = TimerManager::uptimeNs() + deadlinePeriodNs;
        TimerManager::arm(task.deadlineTimeout, TimerManager::tickAfter(deadlinePeriodNs));
    } else {
        task.setDeadlineScope(false);
        task.deadlineAtNextBlock = true;
    }
    Scheduler::requeue(task);
    return Status::Ok;
}

Status SchedulerAgent::ClearDeadline()
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    Task& task = Scheduler::current();
    if (!task.inDeadlineScope && !task.deadlineAtNextBlock) {
        return Status::InvalidArgument; // Not in a real-time scope.
    }
    Scheduler::makeUnready(task);
    TimerManager::cancel(task.deadlineTimeout);
    task.setDeadlineScope(false);
    task.deadlineAtNextBlock = false;
    Scheduler::requeue(task);
    return Status::Ok;
}

Status SchedulerAgent::SetTimeSliceQuantum(uint64_t nanoseconds)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    const uint64_t period = TimerManager::tickPeriodNs();
    if (nanoseconds < period || nanoseconds / period > 0xFFFFFFFFull) {
        return Status::InvalidArgument; // A quantum is at least one tick.
    }
    Scheduler::setQuantumTicks(static_cast<uint32_t>((nanoseconds + period / 2) / period));
    return Status::Ok;
}

Status SchedulerAgent::StartProfiling(ObjectId id)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return task.status();
    }
    arch_x86::InterruptGuard guard;
    Task& t = *task.value();
    t.profiling = true;
    t.refreshSwitchWork();
    t.profileAccumulatedNs = 0;
    t.runStartedNs = TimerManager::preciseUptimeNs();
    return Status::Ok;
}

Status SchedulerAgent::StopProfiling(ObjectId id)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return task.status();
    }
    arch_x86::InterruptGuard guard;
    Task& t = *task.value();
    if (!t.profiling) {
        return Status::InvalidArgument; // StartProfiling was not called.
    }
    if (&t == &Scheduler::current()) {
        t.profileAccumulatedNs += TimerManager::preciseUptimeNs() - t.runStartedNs;
    }
    const uint64_t sample = t.profileAccumulatedNs;
    t.profiling = false;
    t.refreshSwitchWork();
    if (t.profileSamples == 0 || sample < t.profileMinimumNs) {
        t.profileMinimumNs = sample;
    }
    if (sample > t.profileMaximumNs) {
        t.profileMaximumNs = sample;
    }
    t.profileTotalNs += sample;
    ++t.profileSamples;
    return Status::Ok;
}

Result<TimingInfo> SchedulerAgent::GetTimingInfo(ObjectId id)
{
    const Result<Task*> task = TaskManager::resolve(id);
    if (!task.ok()) {
        return task.status();
    }
    arch_x86::InterruptGuard guard;
    const Task& t = *task.value();
    TimingInfo info{};
    info.samples = t.profileSamples;
    if (t.profileSamples != 0) {
        info.minimumNs = t.profileMinimumNs;
        info.maximumNs = t.profileMaximumNs;
        info.averageNs = t.profileTotalNs / t.profileSamples;
    }
    return info;
}

} // namespace dcos
