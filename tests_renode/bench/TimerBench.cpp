// Benchmarks of the timer agent's primitives (seed 7.5, Table 9.4).
//
// The object count is the number of timer objects, all owned by the shell.
// All but the newest ("target") have an alarm set, so the time wheel holds
// count - 1 time-outs: watch-dog alarms due one hour ahead on consecutive
// ticks, which spreads them over every slot (about count / 257 per slot).
// The measured alarms are due two hours ahead, after everything already in
// their slot: the case the wheel's sorted slots are built for, insertion at
// the tail. Timer.SetWatchDogAlarmEarliest arms one due before everything in
// its slot instead, the worst case, which walks the slot.
#include "BenchSupport.hpp"

#include <dcos/GregorianCalendar.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace bench {
namespace {

using dcos::AlarmNotification;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::timerAgent;

constexpr uint64_t kMillisecond = 1000000;
constexpr uint64_t kHour = 3600ull * 1000 * kMillisecond;
// An event the shell never waits for; no alarm here goes off during a run anyway.
constexpr AlarmNotification kNotification = AlarmNotification::event(1u << 20);

enum class Armed : uint8_t { WatchDog, DayClock };

ObjectId timers[maximumObjectCount];
uint32_t timerCount = 0;
ObjectId target;
volatile uint32_t lastValue;

uint64_t timeOfDay() { return dcos::internal::TimerManager::timeOfDayNs(); }

Result<ObjectId> createTimer(const char* name)
{
    return createGrowing([&] { return timerAgent.Create(name, dcos::Visibility::Local); }, timerAgent.AddObjects);
}

// Every benchmark here starts with the clock set to 2024-01-01 00:00: the
// 64-bit divisions that convert times in full cost more for later dates (one
// loop step per quotient bit), so a fixed, realistic date keeps the figures
// comparable from run to run.
constexpr dcos::DateTime clockSetting{2024, 1, 1, 0, 0, 0, 0, dcos::Weekday::Monday};

// Creates timers until count exist, the last one the unarmed "target".
Status populateArmed(uint32_t count, Armed armed)
{
    if (timerCount == 0) {
        const Status set = timerAgent.SetSystemClock(clockSetting);
        if (set != Status::Ok) {
            return set;
        }
    }
    const uint64_t now = timeOfDay();
    while (timerCount < count) {
        const bool last = timerCount + 1 == count;
        const Result<ObjectId> id = createTimer(last ? "target" : nullptr);
        if (!id.ok()) {
            return id.status();
        }
        timers[timerCount] = id.value();
        if (last) {
            target = id.value();
        } else {
            const uint64_t ahead = kHour + timerCount * kMillisecond;
            const Status set = armed == Armed::WatchDog
                                   ? timerAgent.SetWatchDogAlarm(id.value(), ahead, kNotification)
                                   : timerAgent.SetDayClockAlarm(
                                         id.value(), dcos::GregorianCalendar::fromNanoseconds(now + ahead), kNotification);
            if (set != Status::Ok) {
                return set;
            }
        }
        ++timerCount;
    }
    return Status::Ok;
}

Status populate(uint32_t count) { return populateArmed(count, Armed::WatchDog); }

void clearAll()
{
    while (timerCount > 0) {
        (void)timerAgent.Delete(timers[--timerCount]);
    }
    target = ObjectId::null();
}

// --- Timer.Create and Timer.Delete.

ObjectId created;

Status populateButOne(uint32_t count) { return populate(count - 1); }

void createOneTimer()
{
    const Result<ObjectId> id = timerAgent.Create(nullptr, dcos::Visibility::Local);
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void deleteCreated() { (void)timerAgent.Delete(created); }

void deleteTarget() { check(timerAgent.Delete(target)); }

void recreateTarget()
{
    const Result<ObjectId> id = timerAgent.Create("target", dcos::Visibility::Local);
    check(id.status());
    target = id.ok() ? id.value() : ObjectId::null();
    timers[timerCount - 1] = target;
}

// --- The alarms, each on the unarmed target and cancelled again.

dcos::DateTime dayClockTime;

void setWatchDogAlarm() { check(timerAgent.SetWatchDogAlarm(target, 2 * kHour, kNotification)); }
void setEarliestWatchDogAlarm() { check(timerAgent.SetWatchDogAlarm(target, kMillisecond, kNotification)); }
void setDayClockAlarm() { check(timerAgent.SetDayClockAlarm(target, dayClockTime, kNotification)); }
void setPeriodicAlarm() { check(timerAgent.SetPeriodicAlarm(target, 2 * kHour, kNotification)); }
void cancelAlarm() { check(timerAgent.CancelAlarm(target)); }

Status populateForDayClock(uint32_t count)
{
    const Status status = populate(count);
    dayClockTime = dcos::GregorianCalendar::fromNanoseconds(timeOfDay() + 2 * kHour);
    return status;
}

Status populateWithTargetArmed(uint32_t count)
{
    const Status status = populate(count);
    return status != Status::Ok ? status : timerAgent.SetWatchDogAlarm(target, 2 * kHour, kNotification);
}

// --- Timer.GetSystemClock and Timer.SetSystemClock. GetSystemClock is
// measured in its common case, a read within the second of the previous one
// (the timer agent's calendar cache). Setting the clock used to move every
// day-clock alarm with it; they are keyed by time of day now and stay where
// they are, and the other timers carry day-clock alarms, an hour and more
// after 2024-01-01 00:00, to show that. Every measured call sets the clock
// a second ahead, to 2024-01-01 00:00:01, and the unmeasured restore sets
// it back to 00:00. Setting it back by less than a tick, as the same
// setting made again would, moves the day-clock wheel's cursor back a tick
// or not depending on where in the tick the call falls (14 instructions
// once in a few hundred calls); a second ahead is the same path every time.

Status populateWithDayClockAlarms(uint32_t count) { return populateArmed(count, Armed::DayClock); }

void getSystemClock()
{
    const Result<dcos::DateTime> now = timerAgent.GetSystemClock();
    check(now.status());
    lastValue = now.ok() ? now.value().nanosecond : 0;
}

constexpr dcos::DateTime clockSettingPlusOne{2024, 1, 1, 0, 0, 1, 0, dcos::Weekday::Monday};

void setSystemClock() { check(timerAgent.SetSystemClock(clockSettingPlusOne)); }
void setSystemClockBack() { check(timerAgent.SetSystemClock(clockSetting)); }

// --- Timer.XferOwnership of the target from the shell to the shell.

void transferOwnership() { check(timerAgent.XferOwnership(target, self())); }

// --- Timer.NameToObject (configuration): the newest timer, "target".

void nameToObject()
{
    const Result<ObjectId> id = timerAgent.NameToObject("target");
    check(id.status());
    lastValue = id.ok() ? id.value().raw() : 0;
}

} // namespace

DCOS_BENCHMARK(timerCreateBench, "Timer.Create", populateButOne, createOneTimer, Cost::Constant,
               .restore = deleteCreated, .teardown = clearAll);
DCOS_BENCHMARK(timerDeleteBench, "Timer.Delete", populate, deleteTarget, Cost::Constant, .restore = recreateTarget,
               .teardown = clearAll);
DCOS_BENCHMARK(timerSetWatchDogAlarmBench, "Timer.SetWatchDogAlarm", populate, setWatchDogAlarm, Cost::Constant,
               .restore = cancelAlarm, .teardown = clearAll);
DCOS_BENCHMARK(timerSetWatchDogAlarmEarliestBench, "Timer.SetWatchDogAlarmEarliest", populate,
               setEarliestWatchDogAlarm, Cost::Variable, .restore = cancelAlarm, .teardown = clearAll);
DCOS_BENCHMARK(timerSetDayClockAlarmBench, "Timer.SetDayClockAlarm", populateForDayClock, setDayClockAlarm,
               Cost::Constant, .restore = cancelAlarm, .teardown = clearAll);
DCOS_BENCHMARK(timerSetPeriodicAlarmBench, "Timer.SetPeriodicAlarm", populate, setPeriodicAlarm, Cost::Constant,
               .restore = cancelAlarm, .teardown = clearAll);
DCOS_BENCHMARK(timerCancelAlarmBench, "Timer.CancelAlarm", populateWithTargetArmed, cancelAlarm, Cost::Constant,
               .restore = setWatchDogAlarm, .teardown = clearAll);
DCOS_BENCHMARK(timerGetSystemClockBench, "Timer.GetSystemClock", populate, getSystemClock, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(timerSetSystemClockBench, "Timer.SetSystemClock", populateWithDayClockAlarms, setSystemClock,
               Cost::Constant, .restore = setSystemClockBack, .teardown = clearAll);
DCOS_BENCHMARK(timerXferOwnershipBench, "Timer.XferOwnership", populate, transferOwnership, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(timerNameToObjectBench, "Timer.NameToObject", populate, nameToObject, Cost::Variable,
               .teardown = clearAll);

} // namespace bench
