// Host tests for the Gregorian calendar conversion (dissertation 7.5).
#include <dcos/GregorianCalendar.hpp>

#include <gtest/gtest.h>

#include <random>

using dcos::DateTime;
using dcos::GregorianCalendar;
using dcos::Status;
using dcos::Weekday;

namespace {

constexpr uint64_t kSecond = 1000000000ull;
constexpr uint64_t kDay = 86400ull * kSecond;

DateTime date(uint16_t year, uint8_t month, uint8_t day, uint8_t hour = 0, uint8_t minute = 0, uint8_t second = 0,
              uint32_t nanosecond = 0)
{
    DateTime time;
    time.year = year;
    time.month = month;
    time.day = day;
    time.hour = hour;
    time.minute = minute;
    time.second = second;
    time.nanosecond = nanosecond;
    return time;
}

void expectDate(const DateTime& time, uint16_t year, uint8_t month, uint8_t day, Weekday weekday)
{
    EXPECT_EQ(time.year, year);
    EXPECT_EQ(time.month, month);
    EXPECT_EQ(time.day, day);
    EXPECT_EQ(time.weekday, weekday);
}

} // namespace

TEST(GregorianCalendarTest, LeapYearRules)
{
    EXPECT_FALSE(GregorianCalendar::isLeapYear(1970));
    EXPECT_TRUE(GregorianCalendar::isLeapYear(1972));
    EXPECT_TRUE(GregorianCalendar::isLeapYear(2000));
    EXPECT_FALSE(GregorianCalendar::isLeapYear(2100));
    EXPECT_FALSE(GregorianCalendar::isLeapYear(2200));
    EXPECT_TRUE(GregorianCalendar::isLeapYear(2400));
    EXPECT_EQ(GregorianCalendar::daysInMonth(2000, 2), 29);
    EXPECT_EQ(GregorianCalendar::daysInMonth(2100, 2), 28);
    EXPECT_EQ(GregorianCalendar::daysInMonth(2023, 4), 30);
    EXPECT_EQ(GregorianCalendar::daysInMonth(2023, 12), 31);
    EXPECT_EQ(GregorianCalendar::daysInMonth(2023, 13), 0);
}

TEST(GregorianCalendarTest, EpochIsThursdayFirstOfJanuary1970)
{
    const DateTime epoch = GregorianCalendar::fromNanoseconds(0);
    expectDate(epoch, 1970, 1, 1, Weekday::Thursday);
    EXPECT_EQ(epoch.hour, 0);
    EXPECT_EQ(epoch.minute, 0);
    EXPECT_EQ(epoch.second, 0);
    EXPECT_EQ(epoch.nanosecond, 0u);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(date(1970, 1, 1)).value(), 0u);
}

TEST(GregorianCalendarTest, KnownTimestamps)
{
    // 2000-02-29T12:34:56.789 UTC, a Tuesday: Unix time 951827696.
    const uint64_t leapDay = 951827696ull * kSecond + 789000000;
    const DateTime t = GregorianCalendar::fromNanoseconds(leapDay);
    expectDate(t, 2000, 2, 29, Weekday::Tuesday);
    EXPECT_EQ(t.hour, 12);
    EXPECT_EQ(t.minute, 34);
    EXPECT_EQ(t.second, 56);
    EXPECT_EQ(t.nanosecond, 789000000u);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(date(2000, 2, 29, 12, 34, 56, 789000000)).value(), leapDay);

    // 2038-01-19T03:14:08, one past the signed 32-bit time_t limit, a Tuesday.
    const uint64_t y2038 = 2147483648ull * kSecond;
    expectDate(GregorianCalendar::fromNanoseconds(y2038), 2038, 1, 19, Weekday::Tuesday);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(date(2038, 1, 19, 3, 14, 8)).value(), y2038);

    // 1999-12-31T23:59:59.999999999 is the last instant before 2000.
    const DateTime last = GregorianCalendar::fromNanoseconds(946684800ull * kSecond - 1);
    expectDate(last, 1999, 12, 31, Weekday::Friday);
    EXPECT_EQ(last.hour, 23);
    EXPECT_EQ(last.minute, 59);
    EXPECT_EQ(last.second, 59);
    EXPECT_EQ(last.nanosecond, 999999999u);
}

TEST(GregorianCalendarTest, Year2100IsNotALeapYear)
{
    // 2100-02-28 is Unix day 47540, a Sunday; the next day is March 1.
    const uint64_t feb28 = 4107456000ull * kSecond;
    expectDate(GregorianCalendar::fromNanoseconds(feb28), 2100, 2, 28, Weekday::Sunday);
    expectDate(GregorianCalendar::fromNanoseconds(feb28 + kDay), 2100, 3, 1, Weekday::Monday);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(date(2100, 3, 1)).value(), feb28 + kDay);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(date(2100, 2, 29)).status(), Status::InvalidArgument);
}

TEST(GregorianCalendarTest, Year2400IsALeapYear)
{
    // 2400-02-29 is Unix day 157113, a Tuesday.
    const uint64_t feb29 = 157113ull * kDay;
    expectDate(GregorianCalendar::fromNanoseconds(feb29), 2400, 2, 29, Weekday::Tuesday);
    expectDate(GregorianCalendar::fromNanoseconds(feb29 + kDay), 2400, 3, 1, Weekday::Wednesday);
    expectDate(GregorianCalendar::fromNanoseconds(feb29 - kDay), 2400, 2, 28, Weekday::Monday);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(date(2400, 2, 29)).value(), feb29);
}

TEST(GregorianCalendarTest, EndOfRange)
{
    const DateTime end = GregorianCalendar::fromNanoseconds(UINT64_MAX);
    expectDate(end, 2554, 7, 21, Weekday::Sunday);
    EXPECT_EQ(end.hour, 23);
    EXPECT_EQ(end.minute, 34);
    EXPECT_EQ(end.second, 33);
    EXPECT_EQ(end.nanosecond, 709551615u);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(end).value(), UINT64_MAX);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(date(2554, 7, 21, 23, 34, 33, 709551616)).status(),
              Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::toNanoseconds(date(2554, 7, 22)).status(), Status::InvalidArgument);
    EXPECT_TRUE(GregorianCalendar::toNanoseconds(date(2500, 12, 31, 23, 59, 59, 999999999)).ok());
}

TEST(GregorianCalendarTest, InvalidDatesAreRejected)
{
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 13, 1)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 0, 1)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 1, 0)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 2, 29)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2024, 2, 30)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 4, 31)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 1, 1, 24)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 1, 1, 0, 60)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 1, 1, 0, 0, 60)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 1, 1, 0, 0, 0, 1000000000)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(1969, 12, 31)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2555, 1, 1)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(65535, 1, 1)), Status::InvalidArgument);
    EXPECT_EQ(GregorianCalendar::validate(date(2024, 2, 29)), Status::Ok);
    EXPECT_EQ(GregorianCalendar::validate(date(2023, 12, 31, 23, 59, 59, 999999999)), Status::Ok);
}

TEST(GregorianCalendarTest, EveryDayFrom1970To2555IsConsecutive)
{
    // Walks day by day and checks the calendar advances exactly like a hand count.
    uint16_t year = 1970;
    uint8_t month = 1;
    uint8_t day = 1;
    for (uint32_t days = 0; days < 213503; ++days) {
        const DateTime t = GregorianCalendar::fromNanoseconds(days * kDay);
        ASSERT_EQ(t.year, year);
        ASSERT_EQ(t.month, month);
        ASSERT_EQ(t.day, day);
        ASSERT_EQ(static_cast<uint32_t>(t.weekday), (days + 4) % 7);
        ASSERT_EQ(GregorianCalendar::daysSinceEpoch(year, month, day), days);
        if (++day > GregorianCalendar::daysInMonth(year, month)) {
            day = 1;
            if (++month > 12) {
                month = 1;
                ++year;
            }
        }
    }
}

TEST(GregorianCalendarTest, RandomRoundTrip)
{
    std::mt19937_64 random(2024);
    for (int i = 0; i < 200000; ++i) {
        const uint64_t ns = random();
        const DateTime t = GregorianCalendar::fromNanoseconds(ns);
        ASSERT_EQ(GregorianCalendar::validate(t), Status::Ok);
        const auto back = GregorianCalendar::toNanoseconds(t);
        ASSERT_TRUE(back.ok());
        ASSERT_EQ(back.value(), ns);
    }
}

TEST(GregorianCalendarTest, WeekdayIsIgnoredOnInput)
{
    DateTime t = date(2000, 1, 1);
    t.weekday = Weekday::Monday;
    EXPECT_EQ(GregorianCalendar::toNanoseconds(t).value(), 946684800ull * kSecond);
    EXPECT_EQ(GregorianCalendar::fromNanoseconds(946684800ull * kSecond).weekday, Weekday::Saturday);
}
