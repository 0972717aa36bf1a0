// Conversion between the system clock and the Gregorian calendar (dissertation 7.5).
//
// The timer agent keeps time as a 64-bit count of nanoseconds. Time of day is
// derived from it on demand, applying the Gregorian leap year rules (every
// fourth year, except centuries, except every fourth century). All
// arithmetic is integer; the firmware has no floating point in the kernel.
#pragma once

#include <dcos/DateTime.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace dcos {

/// Converts nanoseconds since 1970-01-01T00:00:00 UTC (no leap seconds) to DateTime and back.
///
/// The full uint64_t range is valid: it ends at 2554-07-21T23:34:33.709551615.
class GregorianCalendar {
public:
    /// Nanoseconds in one second.
    static constexpr uint64_t kNanosecondsPerSecond = 1000000000;
    /// Seconds in one day (no leap seconds).
    static constexpr uint32_t kSecondsPerDay = 86400;
    /// First year that can be represented.
    static constexpr uint16_t kMinYear = 1970;
    /// Last year of which at least a part can be represented.
    static constexpr uint16_t kMaxYear = 2554;

    /// Whether @p year has a February 29. Cost O(1).
    static bool isLeapYear(uint16_t year);

    /// Number of days of @p month (1..12) in @p year, or 0 for an invalid month. Cost O(1).
    static uint8_t daysInMonth(uint16_t year, uint8_t month);

    /// Checks every field of @p time; the weekday is ignored because it is derived.
    ///
    /// Fails with InvalidArgument for a field out of range, a day that does
    /// not exist in its month (e.g. February 29 of a common year), or a time
    /// past the end of the representable range. Cost O(1).
    static Status validate(const DateTime& time);

    /// Breaks @p nanoseconds since the epoch down into calendar fields. Cost O(1).
    static DateTime fromNanoseconds(uint64_t nanoseconds);

    /// Converts a validated @p time to nanoseconds since the epoch.
    ///
    /// Fails with InvalidArgument when validate() does. Cost O(1).
    static Result<uint64_t> toNanoseconds(const DateTime& time);

    /// Number of days from 1970-01-01 to the given valid date. Cost O(1).
    static uint32_t daysSinceEpoch(uint16_t year, uint8_t month, uint8_t day);
};

} // namespace dcos
