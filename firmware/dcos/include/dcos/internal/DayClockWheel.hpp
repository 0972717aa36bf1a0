// The timer agent's time-outs due at a time of day (day-clock alarms,
// SleepTill), kept so that setting the clock costs the same for any number of
// them.
//
// The seed keeps the clock as a base (the time of day when the tick started)
// plus the nanoseconds ticked since, and SetSystemClock changes only the
// base. A time-out armed on the tick wheel for a time of day is keyed by the
// tick at which that time is reached with the base in force, so each one
// had to be found and moved when the base changed: a walk over every timer
// and task with interrupts held off (about 1,000,000 instructions with 4,096
// timers). Here such time-outs live on a second time wheel keyed by the time
// of day itself, in "wall ticks" floor(timeOfDay / tick period). At uptime
// tick t the time of day is base + t * period, whose wall tick is
// floor(base / period) + t, so the wheel is turned one wall tick per tick
// and setting the clock only changes where it is turned to:
//  - set back, the wheel's clock is wound back (TimeWheel::rewind, O(1));
//    everything on it was due after the old time and so after the new one;
//  - set forward, the next tick turns the wheel on to the new wall tick and
//    fires what the new time has reached, visiting each slot at most once
//    (TimeWheel::popExpired), plus O(1) per time-out that fires.
// A time-out fires at the first tick whose time of day is at or after its
// time, as before. Its wall tick says only to the tick which it is due: one
// in the wall tick in progress whose time lies later in it than the current
// time is due at the next tick, and so is one armed for a time already
// reached. Those wait on a short list for the next tick, where they are
// checked again (the clock may have been set back in between) and fire
// before the tick wheel's time-outs of that tick: on the single wheel of
// before, a day-clock alarm set before the wait for it fired first at a
// shared tick, and the wait's time-out is commonly due at that very tick.
//
// T derives from TimeWheelNode<> and has the field timeOfDayNs (uint64_t),
// as TimeoutEntry does. An entry armed here is disarmed by the tick wheel's
// cancel (TimeWheel::cancel), which only unlinks it, wherever it is. No
// locking: the timer agent calls everything with interrupts disabled.
#pragma once

#include <dcos/internal/SortedList.hpp>
#include <dcos/internal/TimeWheel.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

template <typename T, size_t Slots>
class DayClockWheel {
public:
    using TickWheel = TimeWheel<T, Slots>;

    explicit DayClockWheel(uint64_t periodNs = 1000000) : periodNs_(periodNs) {}
    DayClockWheel(const DayClockWheel&) = delete;
    DayClockWheel& operator=(const DayClockWheel&) = delete;

    /// Sets the tick period; only before anything is armed and the clock set.
    void setPeriod(uint64_t periodNs) { periodNs_ = periodNs; }

    /// The clock's new base at uptime tick @p tickCount. Cost O(1) (one
    /// 64-bit division), for any number of armed time-outs.
    void setBase(uint64_t baseNs, uint64_t tickCount)
    {
        baseNs_ = baseNs;
        baseTicks_ = baseNs / periodNs_;
        wall_.rewind(baseTicks_ + tickCount);
    }

    /// Arms @p entry, which must not be armed, for @p timeOfDayNs. The clock
    /// stands at tick @p tickCount.
    void arm(T& entry, uint64_t timeOfDayNs, uint64_t tickCount)
    {
        entry.timeOfDayNs = timeOfDayNs;
        place(entry, tickCount);
    }

    /// At tick @p tickCount, @p incrementNs after the base, before the tick
    /// wheel: hands every time-out the time of day has reached to
    /// @p fire(T&), those held for this tick first, and holds those due at
    /// the next tick for it.
    template <typename Fire>
    void advance(uint64_t tickCount, uint64_t incrementNs, Fire&& fire)
    {
        const uint64_t now = baseNs_ + incrementNs;
        SortedList<T, uint64_t>& held = nextTick_[tickCount & 1];
        while (T* entry = held.popFront()) {
            if (entry->timeOfDayNs <= now) {
                fire(*entry);
            } else {
                place(*entry, tickCount); // The clock was set back.
            }
        }
        while (T* entry = wall_.popExpired(baseTicks_ + tickCount)) {
            if (entry->timeOfDayNs <= now) {
                fire(*entry);
            } else {
                holdForNextTick(*entry, tickCount);
            }
        }
    }

    /// Time-outs armed here, for tests and diagnostics. Cost O(Slots + N).
    size_t size() const { return wall_.size() + nextTick_[0].size() + nextTick_[1].size(); }

private:
    // Puts an entry, not armed, where its time needs it at tick tickCount:
    // one in a later wall tick on the wheel, any other on the list for the
    // next tick.
    void place(T& entry, uint64_t tickCount)
    {
        const uint64_t wallTick = entry.timeOfDayNs / periodNs_;
        if (wallTick > baseTicks_ + tickCount) {
            (void)wall_.insert(entry, wallTick); // Cannot fail: not armed.
        } else {
            holdForNextTick(entry, tickCount);
        }
    }

    void holdForNextTick(T& entry, uint64_t tickCount)
    {
        // One key for all: first held, first fired.
        nextTick_[(tickCount + 1) & 1].insert(entry, 0);
    }

    TimeWheel<T, Slots> wall_;
    // The time-outs due at the next tick, by the parity of that tick: those
    // of tick t are taken at tick t, while any held again then go to t + 1.
    SortedList<T, uint64_t> nextTick_[2];
    uint64_t periodNs_;
    uint64_t baseNs_ = 0;
    uint64_t baseTicks_ = 0;
};

} // namespace dcos::internal
