// The timer agent's kernel side (seed 7.5): the system clock, the time
// wheel of time-outs and the software timer objects.
//
// The clock is two 64-bit nanosecond counts, as the seed's Fig. 7.8 shows:
// the base (time of day at the moment the tick started) and the increment
// (nanoseconds ticked since). SetSystemClock changes only the base, so every
// interval and time-out in progress is undisturbed. Time-outs due at a time
// of day (day-clock alarms, SleepTill) are kept apart, keyed by time of day
// (DayClockWheel.hpp), so that they follow the clock without being touched
// when it is set: SetSystemClock costs the same for any number of them.
// GetSystemClock converts through a cache of the current second's calendar
// (CalendarCache.hpp) instead of dividing.
#pragma once

#include <dcos/DateTime.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/TimeoutEntry.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

class TimerManager {
public:
    /// Starts the clock with the board's exact tick period.
    static void initialise(uint64_t tickPeriodNs);

    /// The tick interrupt's work: advance the clock, fire due time-outs,
    /// count the running task's time slice. O(1) per tick plus O(1) per
    /// expiring time-out.
    static void onTick();

    static uint64_t ticks();
    static uint64_t tickPeriodNs() { return tickPeriodNs_; }
    /// Nanoseconds since the tick started, at tick granularity.
    static uint64_t uptimeNs();
    /// Nanoseconds since the tick started, refined within the tick by the board.
    static uint64_t preciseUptimeNs();

    /// The first tick at or after ns from now, measured from the precise
    /// time (preciseUptimeNs): a time-out armed for it expires no earlier
    /// than ns and less than one tick later. An ns so large that the sum
    /// passes 2^64 is held there, a wait that never ends, not one that
    /// expires at once.
    static uint64_t tickAfter(uint64_t ns);
    /// The first tick at or after an uptime.
    static uint64_t tickAtUptime(uint64_t uptimeNs);
    /// Arms entry for the absolute tick dueTick.
    static void arm(TimeoutEntry& entry, uint64_t dueTick);
    /// Arms entry for a time of day: it goes off at the first tick at or
    /// after that time, and moves with the clock when SetSystemClock sets it.
    static void armAtTimeOfDay(TimeoutEntry& entry, uint64_t timeOfDayNs);
    /// Disarms entry if it is armed. The test is inline: most waits are
    /// woken before any time-out, or had none, and pay only for it.
    static void cancel(TimeoutEntry& entry)
    {
        if (static_cast<TimeWheelNode<>&>(entry).isLinked()) {
            cancelArmed(entry);
        }
    }
    static void cancelArmed(TimeoutEntry& entry);

    /// Nanoseconds since 1970-01-01 now (base + increment).
    static uint64_t timeOfDayNs();
    static Result<DateTime> getSystemClock();
    static Status setSystemClock(const DateTime& time);
    /// The time of day at @p uptimeNs (an uptime read earlier, such as a
    /// frame's interrupt timestamp), with the base in force now.
    static uint64_t timeOfDayAtUptime(uint64_t uptimeNs);
    /// Sets the base so that the time of day at @p uptimeNs is
    /// @p timeOfDayNs: the global time base's correction (GlobalTime.hpp),
    /// which, like setSystemClock, changes only the base. InvalidArgument
    /// when that would put the base before 1970 or the time past
    /// TimerAgent::kLastClockYear.
    static Status setTimeOfDayAt(uint64_t timeOfDayNs, uint64_t uptimeNs);
    /// Ticks from now until a time of day; 0 when it has passed.
    static Result<uint64_t> nanosecondsUntil(const DateTime& time);

    // Timer objects.
    static Result<ObjectId> createTimer(ObjectId owner, const char* name, Visibility visibility);
    static Status deleteTimer(ObjectId timer, ObjectId caller);
    static Status setWatchDogAlarm(ObjectId timer, ObjectId caller, uint64_t intervalNs, AlarmNotification n);
    static Status setDayClockAlarm(ObjectId timer, ObjectId caller, const DateTime& time, AlarmNotification n);
    static Status setPeriodicAlarm(ObjectId timer, ObjectId caller, uint64_t periodNs, AlarmNotification n);
    static Status cancelAlarm(ObjectId timer, ObjectId caller);
    static Result<ObjectId> timerNameToObject(const char* name, Visibility askingScope = Visibility::Local);
    static Status xferOwnership(ObjectId timer, ObjectId caller, ObjectId newOwner);
    /// The owner of @p timer, a task of this node or of another. O(1).
    static Result<ObjectId> timerOwner(ObjectId timer);
    /// Deletes @p timer if @p owner, a task of another node, still owns it:
    /// that owner is gone (the remote agent learnt so notifying it), as a
    /// local owner's death deletes its timers. O(1).
    static void dropTimerOfLostOwner(ObjectId timer, ObjectId owner);
    /// Deletes every timer owned by a task of @p node, which has started
    /// again, as dropTimerOfLostOwner() deletes one. Returns how many.
    /// O(active timers), each under its own interrupt guard.
    static size_t dropTimersOwnedOnNode(uint16_t node);
    static Status addTimerObjects(size_t count);
    static size_t timerCount();

private:
    static uint64_t tickPeriodNs_;
};

} // namespace dcos::internal
