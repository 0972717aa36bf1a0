// The system agent's interrupt services on the target: blocking services
// refused in handlers, interrupt levels per task and the legal limit
// (seed 7.3.3).
#include "SpareLine.hpp"
#include "KernelTestSupport.hpp"
#include <bsp/Board.hpp>

#include <dcos/SystemAgent.hpp>
#include <dcos/TimerAgent.hpp>


namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::systemAgent;
using dcos::taskAgent;


struct IsrResults {
    Status sleep;
    Status receiveWithTimeout;
    Status receivePoll;
    Status create;
    Status yieldStatus;
    Status postEvent;
};

volatile bool isrRan = false;
IsrResults isrResults;

void tryBlockingInIsr(void*)
{
    isrResults.sleep = taskAgent.SleepFor(1000000);
    isrResults.receiveWithTimeout = taskAgent.ReceiveEvent(1, dcos::EventWait::Any, 1000000).status();
    isrResults.receivePoll = taskAgent.ReceiveEvent(1u << 25, dcos::EventWait::Any, dcos::kPoll).status();
    dcos::TaskAttributes attributes;
    isrResults.create = taskAgent.Create(attributes, [](uintptr_t) {}, 0).status();
    isrResults.postEvent = taskAgent.PostEvent(taskAgent.IdOfSelf(), 1u << 26);
    isrRan = true;
}

bool blockingInIsr(shell::Shell& shell)
{
    isrRan = false;
    bool ok = checkStatus(shell, systemAgent.InstallISR(target_test::spareLine(), tryBlockingInIsr, nullptr), Status::Ok, "InstallISR");
    ok = checkStatus(shell, systemAgent.InstallISR(target_test::spareLine(), tryBlockingInIsr, nullptr), Status::Busy,
                     "a second routine on the same line") && ok;
    // The routine waits for events 0 and 25 with the shell task as the
    // running task; an earlier test may have left them posted, and a present
    // event is taken without blocking, so clear them first.
    (void)taskAgent.ReceiveEvent(1u | (1u << 25), dcos::EventWait::Any, dcos::kPoll);
    target_test::raiseSpareLine();
    ok = check(shell, isrRan, "the routine ran") && ok;
    ok = checkStatus(shell, isrResults.sleep, Status::InInterrupt, "SleepFor in an ISR") && ok;
    ok = checkStatus(shell, isrResults.receiveWithTimeout, Status::InInterrupt, "ReceiveEvent with time-out in an ISR") && ok;
    ok = checkStatus(shell, isrResults.receivePoll, Status::WouldBlock, "a poll is allowed in an ISR") && ok;
    ok = checkStatus(shell, isrResults.create, Status::InInterrupt, "Create in an ISR") && ok;
    ok = checkStatus(shell, isrResults.postEvent, Status::Ok, "PostEvent is allowed in an ISR") && ok;
    ok = check(shell, taskAgent.ReceiveEvent(1u << 26, dcos::EventWait::Any, dcos::kPoll).ok(),
               "the event posted from the ISR arrived") && ok;
    ok = checkStatus(shell, systemAgent.RemoveISR(target_test::spareLine()), Status::Ok, "RemoveISR") && ok;
    ok = checkStatus(shell, systemAgent.RemoveISR(0), Status::InvalidArgument, "the tick cannot be removed") && ok;
    ok = checkStatus(shell, systemAgent.InstallISR(16, tryBlockingInIsr, nullptr), Status::InvalidArgument,
                     "line 16") && ok;
    return ok;
}

DCOS_TARGET_TEST(isrBlockingTest, "isrblock", "blocking services are refused in interrupt handlers", blockingInIsr);

// The 8259A pair's interrupt masks (OCW1), read back directly.
// The lines the interrupt controller holds off, read from the controller
// (the 8259A pair's mask registers, or the I/O APIC's entries).
uint16_t interruptMask() { return bsp::interruptLinesHeldOff(); }

volatile uint16_t maskSeenByOtherTask = 0;

void readMaskEntry(uintptr_t)
{
    maskSeenByOtherTask = interruptMask();
    finished();
}

bool interruptLevels(shell::Shell& shell)
{
    const uint16_t open = interruptMask();
    // Level 11 is IRQ 4 (the console) in the 8259A's order: IRQ 0, 1,
    // 8-15, then 3-7 at levels 10-14.
    dcos::Result<uint8_t> granted = systemAgent.SetInterruptLevel(11);
    bool ok = check(shell, granted.ok() && granted.value() == 11, "SetInterruptLevel(11)");
    const uint16_t held = interruptMask();
    shell.print("mask open %04x, at level 11 %04x\r\n", open, held);
    // The console's line was open and is now held, with 5-7; nothing else changed.
    ok = check(shell, (open & 0x0010) == 0 && (held & 0x00F0) == 0x00F0 && (held & ~0x00F0) == (open & ~0x00F0),
               "level 11 holds off IRQ 4-7 only") && ok;
    // Another task runs with its own level: nothing extra held.
    ok = check(shell, !spawn("level", 10, readMaskEntry).isNull(), "create a task") && ok;
    ok = ok && waitForDone(shell, 1);
    ok = check(shell, maskSeenByOtherTask == open, "another task runs at its own level") && ok;
    ok = check(shell, interruptMask() == held, "the level comes back with the task") && ok;
    // The tick keeps running at the most urgent level.
    granted = systemAgent.SetInterruptLevel(1);
    const uint64_t before = dcos::timerAgent.Uptime();
    (void)taskAgent.SleepFor(5000000);
    ok = check(shell, dcos::timerAgent.Uptime() - before >= 5000000, "the tick is never held off") && ok;
    // The legal limit lowers a request that is too urgent for the priority.
    const uint8_t priority = taskAgent.GetPriority(taskAgent.IdOfSelf()).value();
    ok = checkStatus(shell, systemAgent.SetInterruptLevel(priority, 10), Status::Ok, "set the legal limit") && ok;
    granted = systemAgent.SetInterruptLevel(2);
    ok = check(shell, granted.ok() && granted.value() == 10, "a request above the legal limit gets the limit") && ok;
    (void)systemAgent.SetInterruptLevel(priority, 1);
    ok = checkStatus(shell, systemAgent.SetInterruptLevel(0).status(), Status::InvalidArgument, "level 0") && ok;
    (void)systemAgent.SetInterruptLevel(0xFF);
    ok = check(shell, interruptMask() == open, "level 0xFF holds off nothing") && ok;
    return ok;
}

DCOS_TARGET_TEST(interruptLevelTest, "intlevel", "SetInterruptLevel holds lines per task, within the legal limit",
                 interruptLevels);

} // namespace

} // namespace target_test
