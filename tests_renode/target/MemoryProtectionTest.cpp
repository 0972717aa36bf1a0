// Faults isolated to the task that made them: stack overflows into the
// guard page, null pointer accesses, the kernel tasks' protection, and the
// stack high-water mark (arch_x86/Paging.hpp, arch_x86/FaultTasks.hpp).
//
// Each faulting task runs beside a neighbour whose stack lies right below
// its own in the arena, the place an overflow used to land; the neighbour
// must run on untouched, and the faulting task's stack must come back.
#include "KernelTestSupport.hpp"

#include <dcos/TaskAgent.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TimerManager.hpp>
#include <dcos/internal/StackArena.hpp>
#include <dcos/internal/TaskManager.hpp>

namespace {

using namespace target_test;

constexpr uint64_t kMillisecond = 1000000ull;

volatile uint32_t neighbourBeats = 0;
volatile bool neighbourStop = false;
volatile bool faulterSurvived = false;

// Keeps a stack of its own busy and counts, so the test can see it go on.
void neighbour(uintptr_t)
{
    while (!neighbourStop) {
        volatile uint8_t scratch[512];
        for (size_t i = 0; i < sizeof scratch; ++i) {
            scratch[i] = static_cast<uint8_t>(i);
        }
        neighbourBeats = neighbourBeats + 1;
        (void)dcos::taskAgent.SleepFor(kMillisecond);
    }
    finished();
}

// A local of 6,000 bytes in a 4 KiB stack: the compiler probes each page
// as it moves the stack pointer (-fstack-clash-protection), so the first
// probe below the stack lands in the guard page.
[[gnu::noinline]] void useLargeLocal()
{
    volatile uint8_t large[6000];
    large[0] = 1;
    large[sizeof large - 1] = 2;
    asm volatile("" : : "r"(large) : "memory");
}

void largeLocal(uintptr_t)
{
    useLargeLocal();
    faulterSurvived = true;
}

// Recursion with small frames runs off the bottom of the stack a word at a
// time, past the guard and beyond, if nothing stops it.
[[gnu::noinline]] uint32_t recurse(uint32_t depth)
{
    volatile uint32_t frame[8] = {depth};
    asm volatile("" : : "r"(frame) : "memory");
    return depth == 0 ? frame[0] : recurse(depth - 1) + frame[0];
}

void deepRecursion(uintptr_t)
{
    (void)recurse(1000000);
    faulterSurvived = true;
}

// The address comes through a volatile, so the compiler neither sees a
// null dereference to warn about nor one it may assume unreachable.
volatile uintptr_t nullAddress = 0;

void nullWrite(uintptr_t)
{
    *reinterpret_cast<volatile uint32_t*>(nullAddress) = 0xDEADBEEF;
    faulterSurvived = true;
}

void nullRead(uintptr_t)
{
    const uint32_t value = *reinterpret_cast<volatile uint32_t*>(nullAddress + 8);
    asm volatile("" : : "r"(value));
    faulterSurvived = true;
}

// Leaves 8 bytes of stack and waits for the tick: the processor's push of
// the interrupt frame runs into the guard page, after the interrupt
// controller has put the tick in service. Without delivering the tick after
// all, the controller would hold back IRQ 0 and every less urgent line.
void overflowOnInterrupt(uintptr_t)
{
    const uintptr_t base = reinterpret_cast<uintptr_t>(dcos::internal::Scheduler::current().stackBase);
    asm volatile("movl %0, %%esp\n"
                 "1: jmp 1b"
                 :
                 : "r"(base + 8)
                 : "memory");
}

dcos::ObjectId createTask(const char* name, uint8_t priority, size_t stackSize, dcos::TaskEntry entry)
{
    dcos::TaskAttributes attributes;
    attributes.name = name;
    attributes.priority = priority;
    attributes.stackSize = stackSize;
    const dcos::Result<dcos::ObjectId> id = dcos::taskAgent.Create(attributes, entry, 0);
    return id.ok() ? id.value() : dcos::ObjectId::null();
}

// Starts the faulting task and a neighbour right below it in the arena,
// lets both run, and checks that only the faulting task ended.
bool faultStaysInItsTask(shell::Shell& shell, const char* name, size_t stackSize, dcos::TaskEntry entry)
{
    const size_t stackBefore = dcos::internal::StackArena::freeBytes();
    neighbourBeats = 0;
    neighbourStop = false;
    faulterSurvived = false;
    bool ok = true;
    {
        HoldScheduling hold;
        // The arena hands out blocks from the top down, so the neighbour,
        // created second, lies right below the faulting task's guard page.
        const dcos::ObjectId faulter = createTask(name, 20, stackSize, entry);
        const dcos::ObjectId near = createTask("neighbour", 20, 4096, neighbour);
        ok &= check(shell, !near.isNull() && !faulter.isNull(), "both tasks created");
        if (!ok) {
            return false;
        }
        hold.release();
        (void)dcos::taskAgent.SleepFor(20 * kMillisecond);
        ok &= check(shell, !faulterSurvived, "the faulting task went no further than its fault");
        ok &= checkStatus(shell, dcos::taskAgent.GetState(faulter).status(), dcos::Status::StaleId,
                          "the faulting task is gone");
        const uint32_t beats = neighbourBeats;
        (void)dcos::taskAgent.SleepFor(10 * kMillisecond);
        ok &= check(shell, neighbourBeats > beats, "the neighbour still runs");
        ok &= checkStatus(shell, dcos::taskAgent.GetState(near).status(), dcos::Status::Ok, "the neighbour lives");
        neighbourStop = true;
        ok &= waitForDone(shell, 1);
    }
    (void)dcos::taskAgent.SleepFor(2 * kMillisecond);
    ok &= check(shell, dcos::internal::StackArena::freeBytes() == stackBefore, "every stack came back");
    return ok;
}

bool largeLocalOverflow(shell::Shell& shell)
{
    return faultStaysInItsTask(shell, "largelocal", dcos::kMinimumStackSize, largeLocal);
}

bool recursionOverflow(shell::Shell& shell)
{
    return faultStaysInItsTask(shell, "recursion", 8192, deepRecursion);
}

bool interruptOverflow(shell::Shell& shell)
{
    const uint64_t ticksBefore = dcos::internal::TimerManager::ticks();
    bool ok = faultStaysInItsTask(shell, "irqoverflow", 4096, overflowOnInterrupt);
    const uint64_t ticksAfter = dcos::internal::TimerManager::ticks();
    shell.print("%lu ticks while the tests ran\r\n", static_cast<unsigned long>(ticksAfter - ticksBefore));
    ok &= check(shell, ticksAfter - ticksBefore >= 30, "the tick went on after the fault");
    return ok;
}

bool nullWriteFaults(shell::Shell& shell) { return faultStaysInItsTask(shell, "nullwrite", 4096, nullWrite); }

bool nullReadFaults(shell::Shell& shell) { return faultStaysInItsTask(shell, "nullread", 4096, nullRead); }

// A task of the console's process that is no super user tries to end the
// kernel's tasks; the process rule alone used to let it.
volatile dcos::Status killConsole = dcos::Status::Ok;
volatile dcos::Status suspendConsole = dcos::Status::Ok;
volatile dcos::Status killIdle = dcos::Status::Ok;
volatile dcos::Status suspendIdle = dcos::Status::Ok;

void ordinaryTask(uintptr_t)
{
    const dcos::Result<dcos::ObjectId> console = dcos::taskAgent.NameToObject(dcos::internal::kRootTaskName);
    const dcos::Result<dcos::ObjectId> idle = dcos::taskAgent.NameToObject(dcos::internal::kIdleTaskName);
    if (console.ok() && idle.ok()) {
        killConsole = dcos::taskAgent.KillTask(console.value());
        suspendConsole = dcos::taskAgent.Suspend(console.value());
        killIdle = dcos::taskAgent.KillTask(idle.value());
        suspendIdle = dcos::taskAgent.Suspend(idle.value());
    }
    finished();
}

bool kernelTasksProtected(shell::Shell& shell)
{
    killConsole = dcos::Status::Ok;
    suspendConsole = dcos::Status::Ok;
    killIdle = dcos::Status::Ok;
    suspendIdle = dcos::Status::Ok;
    bool ok = check(shell, !createTask("ordinary", 20, 4096, ordinaryTask).isNull(), "task created");
    ok &= waitForDone(shell, 1);
    ok &= checkStatus(shell, killConsole, dcos::Status::NotPermitted, "KillTask(console)");
    ok &= checkStatus(shell, suspendConsole, dcos::Status::NotPermitted, "Suspend(console)");
    ok &= checkStatus(shell, killIdle, dcos::Status::NotPermitted, "KillTask(idle)");
    ok &= checkStatus(shell, suspendIdle, dcos::Status::NotPermitted, "Suspend(idle)");
    const dcos::Result<dcos::ObjectId> console = dcos::taskAgent.NameToObject(dcos::internal::kRootTaskName);
    ok &= check(shell, console.ok(), "the console task lives");
    return ok;
}

// Uses a known depth of its stack, so the high-water mark can be checked.
void deepUser(uintptr_t)
{
    volatile uint8_t used[3000];
    for (size_t i = 0; i < sizeof used; ++i) {
        used[i] = static_cast<uint8_t>(i);
    }
    (void)dcos::taskAgent.ReceiveEvent(1u << 3, dcos::EventWait::Any, dcos::kWaitForever);
}

bool stackHighWater(shell::Shell& shell)
{
    const dcos::ObjectId id = createTask("deepuser", 20, 8192, deepUser);
    bool ok = check(shell, !id.isNull(), "task created");
    (void)dcos::taskAgent.SleepFor(5 * kMillisecond);
    const dcos::Result<dcos::internal::Task*> task = dcos::internal::TaskManager::resolve(id);
    ok &= check(shell, task.ok(), "task resolved");
    if (task.ok()) {
        const size_t used = dcos::internal::TaskManager::stackHighWater(*task.value());
        shell.print("stack high-water mark %u of %u bytes\r\n", static_cast<unsigned>(used),
                    static_cast<unsigned>(task.value()->stackSize));
        ok &= check(shell, used >= 3000 && used < 3000 + 1024, "the mark shows the 3,000 bytes used");
    }
    ok &= checkStatus(shell, dcos::taskAgent.KillTask(id), dcos::Status::Ok, "KillTask");
    return ok;
}

} // namespace

DCOS_TARGET_TEST(largeLocalOverflowTest, "overflowlocal",
                 "a 6,000-byte local in a 2 KiB stack faults on the guard page; only that task ends",
                 largeLocalOverflow);
DCOS_TARGET_TEST(recursionOverflowTest, "overflowdeep",
                 "unbounded recursion runs into the guard page; only that task ends", recursionOverflow);
DCOS_TARGET_TEST(interruptOverflowTest, "overflowirq",
                 "an interrupt frame pushed into the guard page: only that task ends, the tick goes on",
                 interruptOverflow);
DCOS_TARGET_TEST(nullWriteTest, "nullwrite", "a write through a null pointer faults; only that task ends",
                 nullWriteFaults);
DCOS_TARGET_TEST(nullReadTest, "nullread", "a read near a null pointer faults; only that task ends",
                 nullReadFaults);
DCOS_TARGET_TEST(kernelTasksProtectedTest, "kerneltasks",
                 "a task that is no super user cannot kill or suspend idle or console", kernelTasksProtected);
DCOS_TARGET_TEST(stackHighWaterTest, "stackmark", "the stack high-water mark shows how deep a task went",
                 stackHighWater);
