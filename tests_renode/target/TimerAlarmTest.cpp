// The timer agent on the target: the three kinds of alarm, notification by
// event and by signal, the system clock, and their errors (seed 7.5).
#include "KernelTestSupport.hpp"

#include <bsp/Board.hpp>

#include <dcos/TimerAgent.hpp>

namespace target_test {

namespace {

using dcos::AlarmNotification;
using dcos::EventWait;
using dcos::ObjectId;
using dcos::Status;
using dcos::taskAgent;
using dcos::timerAgent;

constexpr uint64_t kMillisecond = 1000000;

// One alarm awaited: how it ended and when, measured before anything is
// printed. A print can wait for the console, and under -icount the emulated
// clock runs on while the CPU idles for it, so a print between two alarms
// would move the second one's measurement.
struct AlarmWait {
    Status status = Status::Timeout;
    uint64_t elapsedNs = 0;
};

AlarmWait awaitAlarm(uint32_t event, uint64_t start)
{
    const dcos::Result<uint32_t> got = taskAgent.ReceiveEvent(event, EventWait::Any, 1000 * kMillisecond);
    return {got.status(), timerAgent.Uptime() - start};
}

// Reports one awaited alarm against the time it was due.
bool reportAlarm(shell::Shell& shell, const AlarmWait& wait, uint64_t expectedNs, const char* what)
{
    shell.print("%s: %s after %llu ns (expected %llu)\r\n", what,
                wait.status == Status::Ok ? "went off" : dcos::statusName(wait.status),
                static_cast<unsigned long long>(wait.elapsedNs), static_cast<unsigned long long>(expectedNs));
    // An alarm never goes off early, and at most one tick late (plus the
    // tick the interval was rounded up into).
    return check(shell,
                 wait.status == Status::Ok && wait.elapsedNs >= expectedNs &&
                     wait.elapsedNs <= expectedNs + 2 * kMillisecond,
                 what);
}

// Waits for an alarm event and reports how long it took.
bool expectAlarmAfter(shell::Shell& shell, uint32_t event, uint64_t start, uint64_t expectedNs, const char* what)
{
    return reportAlarm(shell, awaitAlarm(event, start), expectedNs, what);
}

volatile unsigned alarmSignals = 0;

void countAlarmSignal(unsigned signal)
{
    if (signal == 7) {
        alarmSignals = alarmSignals + 1;
    }
}

bool alarms(shell::Shell& shell)
{
    const dcos::Result<ObjectId> created = timerAgent.Create("test-timer", dcos::Visibility::Local);
    bool ok = check(shell, created.ok(), "create a timer");
    if (!ok) {
        return false;
    }
    const ObjectId timer = created.value();

    // Watchdog: once, after an interval.
    uint64_t start = timerAgent.Uptime();
    ok = checkStatus(shell, timerAgent.SetWatchDogAlarm(timer, 20 * kMillisecond, AlarmNotification::event(1 << 4)),
                     Status::Ok, "SetWatchDogAlarm") && ok;
    ok = expectAlarmAfter(shell, 1 << 4, start, 20 * kMillisecond, "watchdog alarm") && ok;
    ok = checkStatus(shell, taskAgent.ReceiveEvent(1 << 4, EventWait::Any, 30 * kMillisecond).status(), Status::Timeout,
                     "a watchdog goes off once") && ok;

    // Periodic: every period, without drift.
    start = timerAgent.Uptime();
    ok = checkStatus(shell, timerAgent.SetPeriodicAlarm(timer, 10 * kMillisecond, AlarmNotification::event(1 << 5)),
                     Status::Ok, "SetPeriodicAlarm") && ok;
    constexpr unsigned kPeriods = 5;
    AlarmWait periods[kPeriods];
    for (AlarmWait& wait : periods) {
        wait = awaitAlarm(1 << 5, start);
    }
    for (unsigned period = 1; period <= kPeriods; ++period) {
        ok = reportAlarm(shell, periods[period - 1], period * 10 * kMillisecond, "periodic alarm") && ok;
    }
    ok = checkStatus(shell, timerAgent.CancelAlarm(timer), Status::Ok, "CancelAlarm") && ok;
    ok = checkStatus(shell, taskAgent.ReceiveEvent(1 << 5, EventWait::Any, 30 * kMillisecond).status(), Status::Timeout,
                     "a cancelled alarm stays silent") && ok;
    ok = checkStatus(shell, timerAgent.CancelAlarm(timer), Status::InvalidArgument, "cancel without an alarm") && ok;

    // Day clock: at a time of day, and it follows SetSystemClock.
    dcos::DateTime midnight;
    midnight.year = 2026;
    midnight.month = 12;
    midnight.day = 31;
    midnight.hour = 23;
    midnight.minute = 59;
    midnight.second = 59;
    start = timerAgent.Uptime();
    ok = checkStatus(shell, timerAgent.SetSystemClock(midnight), Status::Ok, "SetSystemClock") && ok;
    dcos::DateTime newYear;
    newYear.year = 2027;
    ok = checkStatus(shell, timerAgent.SetDayClockAlarm(timer, newYear, AlarmNotification::event(1 << 6)), Status::Ok,
                     "SetDayClockAlarm") && ok;
    ok = expectAlarmAfter(shell, 1 << 6, start, 1000 * kMillisecond, "day-clock alarm") && ok;
    const dcos::DateTime now = timerAgent.GetSystemClock().value();
    shell.print("clock now %04u-%02u-%02u %02u:%02u:%02u\r\n", now.year, now.month, now.day, now.hour, now.minute,
                now.second);
    ok = check(shell, now.year == 2027 && now.month == 1 && now.day == 1 && now.hour == 0 && now.second <= 1,
               "the clock rolled over into 2027") && ok;

    // Notification by signal.
    alarmSignals = 0;
    (void)taskAgent.SetSignalHandler(countAlarmSignal);
    ok = checkStatus(shell, timerAgent.SetWatchDogAlarm(timer, 5 * kMillisecond, AlarmNotification::signal(7)),
                     Status::Ok, "alarm by signal") && ok;
    (void)taskAgent.SleepFor(10 * kMillisecond);
    (void)taskAgent.SetSignalHandler(nullptr);
    ok = check(shell, alarmSignals == 1, "the alarm's signal was delivered once") && ok;

    // Errors.
    ok = checkStatus(shell, timerAgent.SetPeriodicAlarm(timer, 0, AlarmNotification::event(1)), Status::InvalidArgument,
                     "a period below one tick") && ok;
    ok = checkStatus(shell, timerAgent.SetWatchDogAlarm(timer, kMillisecond, AlarmNotification::signal(32)),
                     Status::InvalidArgument, "signal 32") && ok;
    dcos::DateTime invalid;
    invalid.year = 2026;
    invalid.month = 2;
    invalid.day = 29;
    ok = checkStatus(shell, timerAgent.SetDayClockAlarm(timer, invalid, AlarmNotification::event(1)),
                     Status::InvalidArgument, "29 February 2026") && ok;
    ok = checkStatus(shell, timerAgent.XferOwnership(timer, ObjectId(bsp::nodeId(), dcos::ObjectType::Task, 0x0F0)),
                     Status::InvalidId, "XferOwnership to no task") && ok;
    ok = checkStatus(shell, timerAgent.XferOwnership(timer, taskAgent.NameToObject("idle").value()), Status::Ok,
                     "XferOwnership to another task") && ok;
    ok = checkStatus(shell, timerAgent.XferOwnership(timer, taskAgent.IdOfSelf()), Status::Ok,
                     "a super user takes it back") && ok;
    ok = checkStatus(shell, timerAgent.Delete(timer), Status::Ok, "Delete") && ok;
    ok = checkStatus(shell, timerAgent.SetWatchDogAlarm(timer, kMillisecond, AlarmNotification::event(1)),
                     Status::StaleId, "use after Delete") && ok;
    ok = checkStatus(shell, timerAgent.SetWatchDogAlarm(taskAgent.IdOfSelf(), kMillisecond, AlarmNotification::event(1)),
                     Status::WrongType, "a task id is not a timer") && ok;
    return ok;
}

DCOS_TARGET_TEST(alarmsTest, "alarms", "watchdog, periodic and day-clock alarms by event and signal", alarms);

bool sleeping(shell::Shell& shell)
{
    uint64_t start = timerAgent.Uptime();
    bool ok = checkStatus(shell, taskAgent.SleepFor(15 * kMillisecond), Status::Ok, "SleepFor");
    uint64_t slept = timerAgent.Uptime() - start;
    shell.print("SleepFor(15 ms) slept %llu ns\r\n", static_cast<unsigned long long>(slept));
    ok = check(shell, slept >= 15 * kMillisecond && slept <= 17 * kMillisecond, "SleepFor interval") && ok;

    dcos::DateTime noon;
    noon.year = 2027;
    noon.month = 6;
    noon.day = 1;
    noon.hour = 12;
    ok = checkStatus(shell, timerAgent.SetSystemClock(noon), Status::Ok, "SetSystemClock") && ok;
    dcos::DateTime later = noon;
    later.nanosecond = 40 * 1000000;
    start = timerAgent.Uptime();
    ok = checkStatus(shell, taskAgent.SleepTill(later), Status::Ok, "SleepTill") && ok;
    slept = timerAgent.Uptime() - start;
    shell.print("SleepTill(+40 ms) slept %llu ns\r\n", static_cast<unsigned long long>(slept));
    ok = check(shell, slept >= 39 * kMillisecond && slept <= 42 * kMillisecond, "SleepTill time of day") && ok;
    ok = checkStatus(shell, taskAgent.SleepFor(dcos::kWaitForever), Status::InvalidArgument, "sleep forever") && ok;
    return ok;
}

DCOS_TARGET_TEST(sleepTest, "sleep", "SleepFor and SleepTill", sleeping);

} // namespace

} // namespace target_test
