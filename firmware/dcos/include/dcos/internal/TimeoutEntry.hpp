// One armed time-out on the timer agent's time wheel.
//
// Tasks (sleep and wait time-outs, deadline supervision) and timer objects
// (alarms) embed these entries; the wheel links them without allocating. The
// kind says which agent handles the expiry, so no virtual call is needed in
// the tick interrupt.
#pragma once

#include <dcos/internal/TimeWheel.hpp>

#include <stdint.h>

namespace dcos::internal {

struct TimeoutEntry : TimeWheelNode<> {
    enum class Kind : uint8_t {
        TaskWake,     ///< A blocked task's time-out: wake it with Status::Timeout.
        DeadlineMiss, ///< A task's deadline passed inside its real-time scope.
        Alarm,        ///< A timer object's alarm.
    };

    constexpr TimeoutEntry(Kind entryKind, void* entryOwner) : kind(entryKind), owner(entryOwner) {}

    Kind kind;
    void* owner;
    /// The time of day a day-clock time-out (day-clock alarm, SleepTill) is due at.
    uint64_t timeOfDayNs = 0;
};

} // namespace dcos::internal
