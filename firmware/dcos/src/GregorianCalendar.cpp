// Gregorian calendar conversion.
//
// The day arithmetic follows Howard Hinnant's days_from_civil and
// civil_from_days algorithms: the year is shifted to start on March 1 so that
// the leap day is the last day of the shifted year, and whole 400-year eras
// (146097 days each) are split off first. This needs no tables and no loops,
// so a conversion costs the same for every date. Only unsigned 32-bit
// arithmetic is used for days because dates before 1970 are not supported.
#include <dcos/GregorianCalendar.hpp>

namespace dcos {

namespace {

// Days from 0000-03-01 to 1970-01-01 in the proleptic Gregorian calendar.
constexpr uint32_t kEpochOffsetDays = 719468;
constexpr uint32_t kDaysPerEra = 146097;

} // namespace

bool GregorianCalendar::isLeapYear(uint16_t year)
{
    return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
}

uint8_t GregorianCalendar::daysInMonth(uint16_t year, uint8_t month)
{
    static constexpr uint8_t kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (month < 1 || month > 12) {
        return 0;
    }
    if (month == 2 && isLeapYear(year)) {
        return 29;
    }
    return kDays[month - 1];
}

uint32_t GregorianCalendar::daysSinceEpoch(uint16_t year, uint8_t month, uint8_t day)
{
    // Shift January and February to the end of the previous year.
    const uint32_t y = static_cast<uint32_t>(year) - (month <= 2 ? 1 : 0);
    const uint32_t era = y / 400;
    const uint32_t yearOfEra = y - era * 400;
    const uint32_t shiftedMonth = month > 2 ? month - 3u : month + 9u;
    const uint32_t dayOfYear = (153 * shiftedMonth + 2) / 5 + day - 1;
    const uint32_t dayOfEra = yearOfEra * 365 + yearOfEra / 4 - yearOfEra / 100 + dayOfYear;
    return era * kDaysPerEra + dayOfEra - kEpochOffsetDays;
}

Status GregorianCalendar::validate(const DateTime& time)
{
    return toNanoseconds(time).status();
}

DateTime GregorianCalendar::fromNanoseconds(uint64_t nanoseconds)
{
    DateTime time;
    const uint64_t seconds = nanoseconds / kNanosecondsPerSecond;
    time.nanosecond = static_cast<uint32_t>(nanoseconds - seconds * kNanosecondsPerSecond);
    // 2^64 ns is about 213504 days, so the day count fits 32 bits.
    const uint32_t days = static_cast<uint32_t>(seconds / kSecondsPerDay);
    uint32_t secondOfDay = static_cast<uint32_t>(seconds - static_cast<uint64_t>(days) * kSecondsPerDay);
    time.hour = static_cast<uint8_t>(secondOfDay / 3600);
    secondOfDay %= 3600;
    time.minute = static_cast<uint8_t>(secondOfDay / 60);
    time.second = static_cast<uint8_t>(secondOfDay % 60);
    time.weekday = static_cast<Weekday>((days + static_cast<uint32_t>(Weekday::Thursday)) % 7);

    const uint32_t shiftedDays = days + kEpochOffsetDays;
    const uint32_t era = shiftedDays / kDaysPerEra;
    const uint32_t dayOfEra = shiftedDays - era * kDaysPerEra;
    const uint32_t yearOfEra = (dayOfEra - dayOfEra / 1460 + dayOfEra / 36524 - dayOfEra / 146096) / 365;
    const uint32_t dayOfYear = dayOfEra - (365 * yearOfEra + yearOfEra / 4 - yearOfEra / 100);
    const uint32_t shiftedMonth = (5 * dayOfYear + 2) / 153;
    time.day = static_cast<uint8_t>(dayOfYear - (153 * shiftedMonth + 2) / 5 + 1);
    time.month = static_cast<uint8_t>(shiftedMonth < 10 ? shiftedMonth + 3 : shiftedMonth - 9);
    time.year = static_cast<uint16_t>(yearOfEra + era * 400 + (time.month <= 2 ? 1 : 0));
    return time;
}

Result<uint64_t> GregorianCalendar::toNanoseconds(const DateTime& time)
{
    if (time.year < kMinYear || time.year > kMaxYear || time.day < 1
        || time.day > daysInMonth(time.year, time.month) || time.hour > 23 || time.minute > 59
        || time.second > 59 || time.nanosecond >= kNanosecondsPerSecond) {
        return Status::InvalidArgument;
    }
    const uint64_t seconds = static_cast<uint64_t>(daysSinceEpoch(time.year, time.month, time.day)) * kSecondsPerDay
        + time.hour * 3600u + time.minute * 60u + time.second;
    // Late in 2554 the nanosecond count no longer fits 64 bits.
    if (seconds > (UINT64_MAX - time.nanosecond) / kNanosecondsPerSecond) {
        return Status::InvalidArgument;
    }
    return seconds * kNanosecondsPerSecond + time.nanosecond;
}

} // namespace dcos
