// Execution profiling and floating-point context on the target (seed 7.4.2, 7.6).
#include "KernelTestSupport.hpp"

#include <dcos/SchedulerAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::schedulerAgent;
using dcos::taskAgent;

constexpr uint64_t kMillisecond = 1000000;

void hogEntry(uintptr_t)
{
    spin(10 * kMillisecond);
    finished();
}

void profiledEntry(uintptr_t)
{
    const ObjectId self = taskAgent.IdOfSelf();
    // Two samples, 5 and 10 ms of CPU time.
    (void)schedulerAgent.StartProfiling(self);
    spin(5 * kMillisecond);
    (void)schedulerAgent.StopProfiling(self);
    (void)schedulerAgent.StartProfiling(self);
    spin(4 * kMillisecond);
    // A more urgent task takes 10 ms in the middle; that time is not ours.
    spawn("hog", 5, hogEntry);
    spin(6 * kMillisecond);
    (void)schedulerAgent.StopProfiling(self);
    finished();
    (void)taskAgent.ReceiveEvent(1u << 20, dcos::EventWait::Any, dcos::kWaitForever);
}

bool profiling(shell::Shell& shell)
{
    const ObjectId task = spawn("profiled", 10, profiledEntry);
    bool ok = check(shell, !task.isNull(), "create the profiled task") && waitForDone(shell, 2);
    const dcos::Result<dcos::TimingInfo> info = schedulerAgent.GetTimingInfo(task);
    ok = check(shell, info.ok(), "GetTimingInfo") && ok;
    const dcos::TimingInfo& t = info.value();
    shell.print("samples %lu, min %llu ns, avg %llu ns, max %llu ns\r\n", static_cast<unsigned long>(t.samples),
                static_cast<unsigned long long>(t.minimumNs), static_cast<unsigned long long>(t.averageNs),
                static_cast<unsigned long long>(t.maximumNs));
    const auto near = [](uint64_t value, uint64_t target) {
        return value >= target && value <= target + kMillisecond / 5;
    };
    ok = check(shell, t.samples == 2, "two samples") && ok;
    ok = check(shell, near(t.minimumNs, 5 * kMillisecond), "min is the 5 ms interval") && ok;
    ok = check(shell, near(t.maximumNs, 10 * kMillisecond), "max is 10 ms, without the 10 ms preemption") && ok;
    ok = check(shell, t.averageNs == (t.minimumNs + t.maximumNs) / 2, "average of the two") && ok;
    ok = checkStatus(shell, schedulerAgent.StopProfiling(task), Status::InvalidArgument, "StopProfiling twice") && ok;
    (void)taskAgent.KillTask(task);
    return ok;
}

DCOS_TARGET_TEST(profilingTest, "profiling", "execution time profiling excludes preemption", profiling);

// Each task keeps its own value on the x87 stack across task switches.
volatile uint32_t fpuResults[2];

void fpuEntry(uintptr_t index)
{
    const uint32_t value = 1000u + 111u * static_cast<uint32_t>(index);
    asm volatile("fildl %0" : : "m"(value));
    for (int i = 0; i < 5; ++i) {
        (void)schedulerAgent.Yield();
    }
    uint32_t out = 0;
    asm volatile("fistpl %0" : "=m"(out));
    fpuResults[index] = out;
    finished();
}

bool fpuContext(shell::Shell& shell)
{
    fpuResults[0] = 0;
    fpuResults[1] = 0;
    {
        HoldScheduling hold;
        spawn("fpu-0", 10, fpuEntry, 0, false, true);
        spawn("fpu-1", 10, fpuEntry, 1, false, true);
    }
    bool ok = waitForDone(shell, 2);
    shell.print("fpu results %lu and %lu\r\n", static_cast<unsigned long>(fpuResults[0]),
                static_cast<unsigned long>(fpuResults[1]));
    return check(shell, fpuResults[0] == 1000 && fpuResults[1] == 1111, "each task kept its FPU register") && ok;
}

DCOS_TARGET_TEST(fpuTest, "fpu", "floating-point tasks keep their FPU state across switches", fpuContext);

} // namespace

} // namespace target_test
