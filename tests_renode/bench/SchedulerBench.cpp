// Benchmarks of the scheduler agent's primitives (seed 7.4, Table 9.3).
//
// The object count is the number of tasks in the system; the tasks besides
// the shell are fillers blocked for ever, the newest named "target".
// SetDeadline and ClearDeadline act on the shell itself; the profiling
// primitives on the target. The scheduling decisions themselves, with ready
// tasks in the queues and the deadline heap, are Kernel.StaticScheduling and
// Kernel.DynamicScheduling (KernelSwitchBench.cpp).
#include "BenchSupport.hpp"

#include <dcos/SchedulerAgent.hpp>
#include <dcos/internal/Scheduler.hpp>

namespace bench {
namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::schedulerAgent;
using dcos::Status;

constexpr uint64_t kMillisecond = 1000000;
constexpr uint64_t kHour = 3600ull * 1000 * kMillisecond;

ObjectId target;
volatile uint64_t lastValue;

Status populate(uint32_t tasks) { return fillTasks(tasks, kBlockedFillerPriority, &target); }

void clearAll()
{
    killTasks();
    target = ObjectId::null();
}

// --- Scheduler.Yield ("overhead only" in the seed): no other task of the
// shell's priority is ready, so the shell keeps the CPU. A Yield that
// switches is Kernel.ContextSwitch.

void yield() { check(schedulerAgent.Yield()); }

// --- Scheduler.SetDeadline ("set now"): the shell enters a deadline scope
// (1 ms of execution within 1 h); ClearDeadline leaves it.

void setDeadline() { check(schedulerAgent.SetDeadline(dcos::DeadlineStart::Now, kMillisecond, kHour)); }
void clearDeadline() { check(schedulerAgent.ClearDeadline()); }

Status populateInScope(uint32_t tasks)
{
    const Status status = populate(tasks);
    return status != Status::Ok ? status : schedulerAgent.SetDeadline(dcos::DeadlineStart::Now, kMillisecond, kHour);
}

void leaveScopeAndClear()
{
    (void)schedulerAgent.ClearDeadline();
    clearAll();
}

// --- Scheduler.SetTimeSliceQuantum (not in the seed's table): 10 ms, the default.

uint32_t savedQuantumTicks;

Status populateSavingQuantum(uint32_t tasks)
{
    savedQuantumTicks = dcos::internal::Scheduler::quantumTicks();
    return populate(tasks);
}

void setQuantum() { check(schedulerAgent.SetTimeSliceQuantum(10 * kMillisecond)); }

void restoreQuantumAndClear()
{
    dcos::internal::Scheduler::setQuantumTicks(savedQuantumTicks);
    clearAll();
}

// --- Scheduler.StartProfiling, StopProfiling and GetTimingInfo of the target.

void startProfiling() { check(schedulerAgent.StartProfiling(target)); }
void stopProfiling() { check(schedulerAgent.StopProfiling(target)); }

Status populateProfiling(uint32_t tasks)
{
    const Status status = populate(tasks);
    return status != Status::Ok ? status : schedulerAgent.StartProfiling(target);
}

Status populateProfiled(uint32_t tasks)
{
    const Status status = populateProfiling(tasks);
    return status != Status::Ok ? status : schedulerAgent.StopProfiling(target);
}

void getTimingInfo()
{
    const Result<dcos::TimingInfo> info = schedulerAgent.GetTimingInfo(target);
    check(info.status());
    lastValue = info.ok() ? info.value().averageNs : 0;
}

} // namespace

DCOS_BENCHMARK(schedulerYieldBench, "Scheduler.Yield", populate, yield, Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(schedulerSetDeadlineBench, "Scheduler.SetDeadline", populate, setDeadline, Cost::Constant,
               .restore = clearDeadline, .teardown = clearAll);
DCOS_BENCHMARK(schedulerClearDeadlineBench, "Scheduler.ClearDeadline", populateInScope, clearDeadline,
               Cost::Constant, .restore = setDeadline, .teardown = leaveScopeAndClear);
DCOS_BENCHMARK(schedulerSetTimeSliceQuantumBench, "Scheduler.SetTimeSliceQuantum", populateSavingQuantum, setQuantum,
               Cost::Constant, .teardown = restoreQuantumAndClear);
DCOS_BENCHMARK(schedulerStartProfilingBench, "Scheduler.StartProfiling", populate, startProfiling, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(schedulerStopProfilingBench, "Scheduler.StopProfiling", populateProfiling, stopProfiling,
               Cost::Constant, .restore = startProfiling, .teardown = clearAll);
DCOS_BENCHMARK(schedulerGetTimingInfoBench, "Scheduler.GetTimingInfo", populateProfiled, getTimingInfo,
               Cost::Constant, .teardown = clearAll);

} // namespace bench
