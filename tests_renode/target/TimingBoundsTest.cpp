// Blocking time-outs, deadlines, SleepTill and huge time-outs in exact
// emulated time (seed 7.4, 7.5, 7.6, 7.9-7.11).
//
// Every blocking time-out must expire no earlier than asked and at most one
// tick late. The kernel measures a time-out from the precise time of the
// call (the tick counter refined by the 8254's count), so the only slack
// left is the tick itself; kWakePath allows for the instructions between
// the expiring tick and the test reading the clock again.
#include "KernelTestSupport.hpp"

#include <dcos/DsmAgent.hpp>
#include <dcos/GregorianCalendar.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SchedulerAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace {

using namespace target_test;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

constexpr uint64_t kMillisecond = 1000000;
constexpr uint64_t kWakePath = 50000; // 50 us of kernel work after the tick.

uint64_t tick() { return dcos::internal::TimerManager::tickPeriodNs(); }

unsigned waitsTimed = 0;

// Times one wait and checks it against [asked, asked + tick + kWakePath].
template <typename Wait>
bool bounded(shell::Shell& shell, const char* what, uint64_t asked, Status expected, Wait wait)
{
    // Start early, midway and late in a tick in turn: where in its tick a
    // wait starts decides how much of the last tick it needs.
    const uint64_t phase = (waitsTimed++ % 3) * 450000;
    const uint64_t tickStart = dcos::internal::TimerManager::uptimeNs();
    while (dcos::timerAgent.Uptime() - tickStart < phase) {
    }
    const uint64_t start = dcos::timerAgent.Uptime();
    const Status status = wait(asked);
    const uint64_t elapsed = dcos::timerAgent.Uptime() - start;
    const bool inBounds = elapsed >= asked && elapsed <= asked + tick() + kWakePath;
    shell.print("%-12s asked %8llu ns, waited %8llu ns%s\r\n", what, static_cast<unsigned long long>(asked),
                static_cast<unsigned long long>(elapsed), inBounds ? "" : "  <- out of bounds");
    bool ok = checkStatus(shell, status, expected, what);
    ok &= check(shell, inBounds, "no earlier than asked, at most one tick late");
    return ok;
}

bool timeoutBounds(shell::Shell& shell)
{
    dcos::SemaphoreAttributes attributes;
    attributes.kind = dcos::SemaphoreKind::Counting;
    attributes.initialCount = 0;
    const Result<ObjectId> semaphore = dcos::semaphoreAgent.Create(attributes);
    const Result<ObjectId> port = dcos::messagePortAgent.Create(nullptr, dcos::Visibility::Local);
    const Result<ObjectId> publisher = dcos::dsmAgent.Create(nullptr, dcos::Visibility::Local);
    bool ok = check(shell, semaphore.ok() && port.ok() && publisher.ok(), "objects created");
    if (!ok) {
        return false;
    }
    const Result<ObjectId> subscription = dcos::dsmAgent.Open(publisher.value());
    ok &= check(shell, subscription.ok(), "subscription opened");
    // A whole tick, a fraction of one, two and a half and ten: the 8254's
    // tick (999,847 ns at 1 kHz) is not a whole number of them.
    const uint64_t asks[] = {kMillisecond, 300000, 2500000, 10 * kMillisecond};
    for (const uint64_t asked : asks) {
        ok &= bounded(shell, "Acquire", asked, Status::Timeout,
                      [&](uint64_t t) { return dcos::semaphoreAgent.Acquire(semaphore.value(), t); });
        ok &= bounded(shell, "Receive", asked, Status::Timeout, [&](uint64_t t) {
            dcos::Message message{};
            return dcos::messagePortAgent.Receive(port.value(), message, t);
        });
        ok &= bounded(shell, "ReceiveEvent", asked, Status::Timeout, [](uint64_t t) {
            return dcos::taskAgent.ReceiveEvent(1u << 7, dcos::EventWait::Any, t).status();
        });
        ok &= bounded(shell, "SleepFor", asked, Status::Ok, [](uint64_t t) { return dcos::taskAgent.SleepFor(t); });
        ok &= bounded(shell, "DSM Read", asked, Status::Timeout, [&](uint64_t t) {
            dcos::DsmPage page{};
            return dcos::dsmAgent.Read(subscription.value(), dcos::kNoDsmData, page, t).status();
        });
    }
    (void)dcos::dsmAgent.Close(subscription.value());
    (void)dcos::dsmAgent.Delete(publisher.value());
    (void)dcos::messagePortAgent.Delete(port.value());
    (void)dcos::semaphoreAgent.Delete(semaphore.value());
    return ok;
}

// A task sleeping until a time of day wakes when the clock reaches it, even
// when the clock is set on the way.
volatile uint64_t wokeAt = 0;

void sleepTillTarget(uintptr_t targetSeconds)
{
    const dcos::DateTime target =
        dcos::GregorianCalendar::fromNanoseconds(uint64_t{targetSeconds} * dcos::GregorianCalendar::kNanosecondsPerSecond);
    (void)dcos::taskAgent.SleepTill(target);
    wokeAt = dcos::timerAgent.Uptime();
    finished();
}

bool sleepTillFollowsTheClock(shell::Shell& shell)
{
    const uint64_t second = dcos::GregorianCalendar::kNanosecondsPerSecond;
    bool ok = checkStatus(shell, dcos::timerAgent.SetSystemClock(dcos::GregorianCalendar::fromNanoseconds(
                                     uint64_t{1900000000} * second)),
                          Status::Ok, "clock set to 2030-03-17");
    wokeAt = 0;
    // Sleep until ten seconds from now; then move the clock to 100 ms before that.
    const uint64_t targetSeconds = 1900000000 + 10;
    ok &= check(shell, !spawn("sleeper", 10, sleepTillTarget, static_cast<uintptr_t>(targetSeconds)).isNull(),
                "sleeper created");
    (void)dcos::taskAgent.SleepFor(5 * kMillisecond);
    ok &= check(shell, wokeAt == 0, "the sleeper sleeps");
    const uint64_t setAt = dcos::timerAgent.Uptime();
    ok &= checkStatus(shell, dcos::timerAgent.SetSystemClock(
                                 dcos::GregorianCalendar::fromNanoseconds(targetSeconds * second - 100 * kMillisecond)),
                      Status::Ok, "clock set to 100 ms before the target");
    ok &= waitForDone(shell, 1, 2 * second);
    const uint64_t delay = wokeAt - setAt;
    shell.print("woke %llu ns after the clock was set 100 ms before its target\r\n",
                static_cast<unsigned long long>(delay));
    ok &= check(shell, wokeAt != 0 && delay >= 100 * kMillisecond - kWakePath &&
                           delay <= 100 * kMillisecond + tick() + kWakePath,
                "SleepTill wakes at the time of day, as the clock now reads it");
    return ok;
}

// Time-outs within a tick of 2^64 ns: a very long wait, never none.
volatile bool hugeSleepReturned = false;
volatile bool hugeReceiveReturned = false;

void hugeSleep(uintptr_t)
{
    (void)dcos::taskAgent.SleepFor(~uint64_t{0} - 1);
    hugeSleepReturned = true;
}

void hugeReceive(uintptr_t)
{
    (void)dcos::taskAgent.ReceiveEvent(1u << 9, dcos::EventWait::Any, ~uint64_t{0} - 1);
    hugeReceiveReturned = true;
}

bool hugeTimeouts(shell::Shell& shell)
{
    hugeSleepReturned = false;
    hugeReceiveReturned = false;
    const ObjectId sleeper = spawn("hugesleep", 10, hugeSleep);
    const ObjectId receiver = spawn("hugerecv", 10, hugeReceive);
    const Result<ObjectId> timer = dcos::timerAgent.Create(nullptr, dcos::Visibility::Local);
    bool ok = check(shell, !sleeper.isNull() && !receiver.isNull() && timer.ok(), "created");
    if (!ok) {
        return false;
    }
    ok &= checkStatus(shell,
                      dcos::timerAgent.SetWatchDogAlarm(timer.value(), ~uint64_t{0} - 2,
                                                        dcos::AlarmNotification::event(1u << 11)),
                      Status::Ok, "SetWatchDogAlarm(2^64 - 2 ns)");
    (void)dcos::taskAgent.SleepFor(20 * kMillisecond);
    ok &= check(shell, !hugeSleepReturned, "SleepFor(2^64 - 2 ns) still sleeps");
    ok &= check(shell, !hugeReceiveReturned, "ReceiveEvent(2^64 - 2 ns) still waits");
    const Result<uint32_t> alarm = dcos::taskAgent.ReceiveEvent(1u << 11, dcos::EventWait::Any, dcos::kPoll);
    ok &= checkStatus(shell, alarm.status(), Status::WouldBlock, "the watchdog alarm has not gone off");
    ok &= checkStatus(shell, dcos::taskAgent.KillTask(sleeper), Status::Ok, "KillTask(sleeper)");
    ok &= checkStatus(shell, dcos::taskAgent.KillTask(receiver), Status::Ok, "KillTask(receiver)");
    ok &= checkStatus(shell, dcos::timerAgent.Delete(timer.value()), Status::Ok, "Delete(timer)");
    return ok;
}

} // namespace

DCOS_TARGET_TEST(timeoutBoundsTest, "timeoutbounds",
                 "Acquire, Receive, ReceiveEvent, SleepFor and DSM Read time out within one tick of the time asked",
                 timeoutBounds);
DCOS_TARGET_TEST(sleepTillClockTest, "sleeptillclock", "SleepTill follows a change of the system clock",
                 sleepTillFollowsTheClock);
DCOS_TARGET_TEST(hugeTimeoutTest, "hugetimeouts", "time-outs within a tick of 2^64 ns wait instead of expiring",
                 hugeTimeouts);
