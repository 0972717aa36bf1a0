// Host tests for GetSystemClock's calendar of the current second: every
// answer through the cache must be exactly GregorianCalendar::fromNanoseconds
// of the same time of day, the reference the clock used before the cache.
#include <dcos/GregorianCalendar.hpp>
#include <dcos/internal/CalendarCache.hpp>

#include <gtest/gtest.h>

#include <random>

using dcos::DateTime;
using dcos::GregorianCalendar;
using dcos::internal::CalendarCache;

namespace {

constexpr uint64_t kSecond = 1000000000ull;
constexpr uint64_t kMinute = 60 * kSecond;
constexpr uint64_t kHour = 60 * kMinute;
constexpr uint64_t kDay = 24 * kHour;
// The 8254's tick at 1 kHz as the uptime counts it.
constexpr uint64_t kTick = 999847;

// The end of the last year SetSystemClock accepts, 2399-12-31T23:59:59.999999999.
uint64_t endOfLastClockYear()
{
    DateTime last;
    last.year = 2399;
    last.month = 12;
    last.day = 31;
    last.hour = 23;
    last.minute = 59;
    last.second = 59;
    last.nanosecond = 999999999;
    return GregorianCalendar::toNanoseconds(last).value();
}

// What TimerManager::getSystemClock does with the cache, without the
// hardware: read, else step a second, else convert in full and cache.
DateTime readClock(CalendarCache& cache, uint64_t baseNs, uint64_t uptimeNs)
{
    DateTime time;
    if (cache.read(uptimeNs, time)) {
        return time;
    }
    if (cache.advance(uptimeNs) && cache.read(uptimeNs, time)) {
        return time;
    }
    time = GregorianCalendar::fromNanoseconds(baseNs + uptimeNs);
    cache.refill(uptimeNs, time);
    return time;
}

void expectSame(const DateTime& expected, const DateTime& actual, uint64_t timeOfDay)
{
    EXPECT_EQ(expected.year, actual.year) << timeOfDay;
    EXPECT_EQ(expected.month, actual.month) << timeOfDay;
    EXPECT_EQ(expected.day, actual.day) << timeOfDay;
    EXPECT_EQ(expected.hour, actual.hour) << timeOfDay;
    EXPECT_EQ(expected.minute, actual.minute) << timeOfDay;
    EXPECT_EQ(expected.second, actual.second) << timeOfDay;
    EXPECT_EQ(expected.nanosecond, actual.nanosecond) << timeOfDay;
    EXPECT_EQ(expected.weekday, actual.weekday) << timeOfDay;
}

// Reads the clock at each uptime in turn and compares with the reference.
void checkWalk(uint64_t baseNs, uint64_t startUptime, const std::vector<uint64_t>& steps)
{
    CalendarCache cache;
    uint64_t uptime = startUptime;
    expectSame(GregorianCalendar::fromNanoseconds(baseNs + uptime), readClock(cache, baseNs, uptime), baseNs + uptime);
    for (const uint64_t step : steps) {
        uptime += step;
        expectSame(GregorianCalendar::fromNanoseconds(baseNs + uptime), readClock(cache, baseNs, uptime),
                   baseNs + uptime);
    }
}

TEST(CalendarCache, AFreshCacheHoldsNothing)
{
    CalendarCache cache;
    DateTime time;
    for (const uint64_t uptime : {uint64_t{0}, uint64_t{1}, kSecond, kDay, uint64_t{1} << 62}) {
        EXPECT_FALSE(cache.read(uptime, time)) << uptime;
        EXPECT_FALSE(cache.advance(uptime)) << uptime;
    }
}

TEST(CalendarCache, ReadsWithinTheCachedSecondOnly)
{
    CalendarCache cache;
    const uint64_t base = 1704067200ull * kSecond + 250000000; // 2024-01-01T00:00:00.25
    const uint64_t uptime = 5 * kSecond;
    cache.refill(uptime, GregorianCalendar::fromNanoseconds(base + uptime));
    DateTime time;
    // The second runs from uptime - 0.25 s to uptime + 0.75 s.
    EXPECT_TRUE(cache.read(uptime - 250000000, time));
    EXPECT_EQ(0u, time.nanosecond);
    EXPECT_TRUE(cache.read(uptime + 749999999, time));
    EXPECT_EQ(999999999u, time.nanosecond);
    EXPECT_FALSE(cache.read(uptime - 250000001, time));
    EXPECT_FALSE(cache.read(uptime + 750000000, time));
}

TEST(CalendarCache, TheSecondMayBeginBeforeUptimeZero)
{
    // Booted at 0.3 s past a second: the cached second starts at uptime
    // -0.3 s, kept modulo 2^64.
    const uint64_t base = 1704067200ull * kSecond + 300000000;
    checkWalk(base, 0, {1, kTick, 699999999 - kTick, 1, 1, kSecond});
}

TEST(CalendarCache, StepsAcrossSecondsMinutesHoursAndDays)
{
    // Starts just before each boundary and steps over it in ticks, single
    // nanoseconds and whole seconds.
    const uint64_t boundaries[] = {
        0,                                        // 1970-01-01, the epoch
        1704067200ull * kSecond,                  // 2024-01-01, a year's start
        1709164800ull * kSecond,                  // 2024-02-29, a leap day
        1709251200ull * kSecond,                  // 2024-03-01, after it
        951782400ull * kSecond,                   // 2000-02-29, a 400-year leap day
        4107542400ull * kSecond,                  // 2100-03-01, after a century's missing leap day
        1704067200ull * kSecond + 13 * kHour,     // an hour
        1704067200ull * kSecond + 13 * kHour + 7 * kMinute, // a minute
        endOfLastClockYear() + 1 - kDay,          // 2399-12-31
        endOfLastClockYear() + 1,                 // 2400-01-01
    };
    for (const uint64_t boundary : boundaries) {
        for (const uint64_t before : {uint64_t{1}, kTick, kSecond - 1, kSecond + 1, 2 * kSecond - 1, kMinute + 5}) {
            if (boundary < before) {
                continue;
            }
            const uint64_t base = boundary - before;
            checkWalk(base, 0, {before - 1, 1, 1, kTick, kSecond - 1, 1, kSecond, kSecond + 1, 2 * kSecond,
                                kDay, kDay - 1, 1});
            std::vector<uint64_t> ticks(2500, kTick); // 2.5 s of ticks.
            checkWalk(base, 0, ticks);
        }
    }
}

TEST(CalendarCache, AgreesWithTheReferenceOverRandomWalks)
{
    std::mt19937_64 random(20261125);
    const uint64_t end = endOfLastClockYear();
    std::uniform_int_distribution<uint64_t> anyTime(0, end);
    // Steps of every size the clock sees: within a second, into the next, a
    // few seconds, across days.
    std::uniform_int_distribution<int> kind(0, 5);
    for (int walk = 0; walk < 2000; ++walk) {
        const uint64_t base = anyTime(random);
        const uint64_t startUptime = random() % (kDay * 30);
        if (base > end - startUptime) {
            continue;
        }
        CalendarCache cache;
        uint64_t uptime = startUptime;
        for (int read = 0; read < 200; ++read) {
            uint64_t step = 0;
            switch (kind(random)) {
            case 0: step = random() % kTick; break;
            case 1: step = random() % kSecond; break;
            case 2: step = kSecond + random() % kSecond; break;
            case 3: step = random() % (10 * kSecond); break;
            case 4: step = random() % (2 * kDay); break;
            default: step = kTick; break;
            }
            if (base + uptime > end - step) {
                break;
            }
            uptime += step;
            const DateTime expected = GregorianCalendar::fromNanoseconds(base + uptime);
            const DateTime actual = readClock(cache, base, uptime);
            expectSame(expected, actual, base + uptime);
            if (::testing::Test::HasFailure()) {
                return;
            }
        }
    }
}

TEST(CalendarCache, ForgetsItsSecondWhenTheClockIsSet)
{
    CalendarCache cache;
    const uint64_t uptime = 10 * kSecond;
    uint64_t base = 1704067200ull * kSecond;
    (void)readClock(cache, base, uptime);
    DateTime time;
    ASSERT_TRUE(cache.read(uptime + 1, time));
    // Set back by 0.4 s and forward by a day: no read hits the old second.
    for (const int64_t change : {int64_t{-400000000}, int64_t{86400} * int64_t{kSecond}}) {
        cache.invalidate(uptime);
        base += static_cast<uint64_t>(change);
        EXPECT_FALSE(cache.read(uptime, time));
        EXPECT_FALSE(cache.advance(uptime + kSecond));
        expectSame(GregorianCalendar::fromNanoseconds(base + uptime + 5), readClock(cache, base, uptime + 5),
                   base + uptime + 5);
    }
}

} // namespace
