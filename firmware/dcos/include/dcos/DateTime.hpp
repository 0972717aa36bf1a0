// Broken-down Gregorian time of day, as GetSystemClock and SetSystemClock exchange it.
#pragma once

#include <stdint.h>

namespace dcos {

/// Day of the week; 1970-01-01 was a Thursday.
enum class Weekday : uint8_t {
    Sunday = 0,    ///< First day of the week as numbered here.
    Monday = 1,    ///< Monday.
    Tuesday = 2,   ///< Tuesday.
    Wednesday = 3, ///< Wednesday.
    Thursday = 4,  ///< Thursday.
    Friday = 5,    ///< Friday.
    Saturday = 6,  ///< Saturday.
};

/// A UTC calendar date and time of day with nanosecond resolution, without leap seconds.
///
/// Field ranges follow the usual human conventions (month and day start at
/// 1) so that values typed at the system engineering interface need no
/// translation. GregorianCalendar converts to and from nanoseconds.
struct DateTime {
    uint16_t year = 1970;              ///< Gregorian year, 1970..2554.
    uint8_t month = 1;                 ///< Month of the year, 1..12.
    uint8_t day = 1;                   ///< Day of the month, 1..28/29/30/31.
    uint8_t hour = 0;                  ///< Hour of the day, 0..23.
    uint8_t minute = 0;                ///< Minute of the hour, 0..59.
    uint8_t second = 0;                ///< Second of the minute, 0..59 (no leap seconds).
    uint32_t nanosecond = 0;           ///< Nanosecond of the second, 0..999999999.
    Weekday weekday = Weekday::Thursday; ///< Output only: filled in by conversion, ignored on input.
};

} // namespace dcos
