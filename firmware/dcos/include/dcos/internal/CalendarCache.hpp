// The calendar of the current second, which lets GetSystemClock convert the
// clock to Gregorian time without dividing.
//
// GregorianCalendar::fromNanoseconds needs two 64-bit divisions (by 10^9 and
// by 86,400), which a 486 does in software, one loop step per quotient bit:
// about 800 instructions. Between two reads of the clock the calendar fields
// rarely change except for the nanoseconds, so the timer agent keeps the
// fields of the second in progress and the uptime at which that second began.
// A read within that second only subtracts and copies; a read in the next
// second steps the seconds, minutes and hours by one; only a read that
// crosses midnight, comes more than a second later, or follows
// SetSystemClock converts in full. Every path gives exactly what
// fromNanoseconds(base + uptime) gives (unit_tests/CalendarCacheTest.cpp).
#pragma once

#include <dcos/DateTime.hpp>
#include <dcos/GregorianCalendar.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

class CalendarCache {
public:
    static constexpr uint64_t kSecond = GregorianCalendar::kNanosecondsPerSecond;

    /// The answer for the first nanosecond of the cached second. A reader
    /// copies it into its result (one REP MOVSL straight into the caller's
    /// return slot) and then fills in the nanosecond with patchNanosecond:
    /// building the answer field by field, or through a DateTime, costs two
    /// to three times the instructions on the i486.
    const Result<DateTime>& answer() const { return answer_; }

    /// Whether @p uptimeNs lies in the cached second; if so @p into is set
    /// to the nanosecond of the second.
    ///
    /// The start is kept as an uptime modulo 2^64 (the second may have begun
    /// before the node started), so one unsigned subtraction and compare
    /// decide: an uptime before the start wraps to a huge value and misses.
    [[gnu::always_inline]] bool contains(uint64_t uptimeNs, uint32_t& into) const
    {
        const uint64_t difference = uptimeNs - secondStartUptimeNs_;
        // The high word and the low word apart: GCC's 64-bit compare with a
        // constant takes two more instructions on the i486.
        if (static_cast<uint32_t>(difference >> 32) != 0 || static_cast<uint32_t>(difference) >= kSecond) {
            return false;
        }
        into = static_cast<uint32_t>(difference);
        return true;
    }

    /// Sets the nanosecond of an answer copied from answer().
    [[gnu::always_inline]] static void patchNanosecond(Result<DateTime>& result, uint32_t nanosecond)
    {
        // One 32-bit store; the layout is checked below.
        __builtin_memcpy(reinterpret_cast<unsigned char*>(&result) + kNanosecondOffset, &nanosecond, 4);
    }

    /// The calendar time at @p uptimeNs when it lies in the cached second.
    bool read(uint64_t uptimeNs, DateTime& time) const
    {
        uint32_t into;
        if (!contains(uptimeNs, into)) {
            return false;
        }
        Result<DateTime> result = answer_;
        patchNanosecond(result, into);
        time = result.value();
        return result.ok();
    }

    /// Moves the cache on to the next second when @p uptimeNs lies in it and
    /// the day does not change; false otherwise, and the cache stays as it is.
    bool advance(uint64_t uptimeNs)
    {
        const uint64_t into = uptimeNs - secondStartUptimeNs_;
        if (into < kSecond || into >= 2 * kSecond) {
            return false;
        }
        DateTime next = second_;
        if (++next.second == 60) {
            next.second = 0;
            if (++next.minute == 60) {
                next.minute = 0;
                if (++next.hour == 24) {
                    return false; // A new day: the date needs the full conversion.
                }
            }
        }
        setSecond(next);
        secondStartUptimeNs_ += kSecond;
        return true;
    }

    /// Caches the second of @p time, the full conversion of the time of day
    /// at @p uptimeNs.
    void refill(uint64_t uptimeNs, const DateTime& time)
    {
        DateTime second = time;
        second.nanosecond = 0;
        setSecond(second);
        secondStartUptimeNs_ = uptimeNs - time.nanosecond;
    }

    /// Forgets the cached second (the clock was set): no read from
    /// @p uptimeNs on hits it for the next 2^63 ns, some 292 years.
    void invalidate(uint64_t uptimeNs) { secondStartUptimeNs_ = uptimeNs + kInvalidDistance; }

private:
    static constexpr uint64_t kInvalidDistance = uint64_t{1} << 63;

    // Where Result<DateTime> keeps the nanosecond: a DateTime is its first
    // member (GCC and Clang lay out a class's members in order).
    static constexpr size_t kNanosecondOffset = offsetof(DateTime, nanosecond);

    void setSecond(const DateTime& second)
    {
        second_ = second;
        answer_ = Result<DateTime>(second);
    }

    DateTime second_;                             // The second in progress, nanosecond 0.
    Result<DateTime> answer_{Status::InvalidArgument}; // The same as an answer.
    uint64_t secondStartUptimeNs_ = kInvalidDistance; // Nothing cached at uptime 0.
};

} // namespace dcos::internal
