// The timer agent's application interface (seed 7.5).
#pragma once

#include <dcos/DateTime.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// How an alarm tells the timer's owner that it went off.
struct AlarmNotification {
    enum class Kind : uint8_t {
        Event,  ///< Post event flags (value = the event set).
        Signal, ///< Send a signal (value = the signal number).
    };
    Kind kind = Kind::Event;
    uint32_t value = 1;

    static constexpr AlarmNotification event(uint32_t events) { return {Kind::Event, events}; }
    static constexpr AlarmNotification signal(unsigned number) { return {Kind::Signal, number}; }
};

/// The timer agent interface object.
class TimerAgent {
public:
    /// The time of day in the Gregorian calendar.
    static Result<DateTime> GetSystemClock();
    /// The last year SetSystemClock accepts. The clock counts nanoseconds
    /// since 1970 in 64 bits, which end in July 2554; stopping at the end
    /// of 2399 leaves the clock more than 150 years to run from any time it
    /// is set to.
    static constexpr uint16_t kLastClockYear = 2399;

    /// Sets the time of day (privileged). Only the clock's base changes, so
    /// intervals already running are not disturbed; day-clock alarms and
    /// SleepTill move with the clock, in time that does not depend on how
    /// many there are. InvalidArgument for a time before the node started or
    /// after kLastClockYear.
    static Status SetSystemClock(const DateTime& time);
    /// Nanoseconds since the system tick started (monotonic).
    static uint64_t Uptime();
    /// Creates a software timer owned by the caller.
    static Result<ObjectId> Create(const char* name, Visibility visibility);
    static Status Delete(ObjectId timer);
    /// Goes off once, after an interval.
    static Status SetWatchDogAlarm(ObjectId timer, uint64_t intervalNs, AlarmNotification notification);
    /// Goes off once, at a time of day.
    static Status SetDayClockAlarm(ObjectId timer, const DateTime& time, AlarmNotification notification);
    /// Goes off every period, first one period from now.
    static Status SetPeriodicAlarm(ObjectId timer, uint64_t periodNs, AlarmNotification notification);
    /// Disarms a set alarm.
    static Status CancelAlarm(ObjectId timer);
    static Result<ObjectId> NameToObject(const char* name);
    /// Hands a timer the caller owns to another task (or to the system, with
    /// the null id), which then receives its alarms and owns it for recovery.
    static Status XferOwnership(ObjectId timer, ObjectId newOwner);
    /// Activates count more timer slots (privileged configuration service).
    static Status AddObjects(size_t count);
};

inline constexpr TimerAgent timerAgent{};

} // namespace dcos
