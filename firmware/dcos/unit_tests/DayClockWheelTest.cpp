// Host tests for the day-clock wheel: time-outs due at a time of day must go
// off at the first tick whose time of day (base + ticks * period) is at or
// after their time, however the clock's base is set in between, forward or
// back, with few or many of them armed.
#include <dcos/internal/DayClockWheel.hpp>

#include <gtest/gtest.h>

#include <random>
#include <vector>

using dcos::internal::DayClockWheel;
using dcos::internal::TimeWheel;
using dcos::internal::TimeWheelNode;

namespace {

// The 8254's tick at 1 kHz as the uptime counts it.
constexpr uint64_t kPeriod = 999847;
// A small prime, so that the wheels turn many times in a test.
constexpr size_t kSlots = 13;

struct Entry : TimeWheelNode<> {
    uint64_t timeOfDayNs = 0;
    size_t index = 0;
    bool armed = false;
    uint64_t firedAt = 0;
};

// The timer agent's tick and clock, with the two wheels, as TimerManager
// drives them.
class Clock {
public:
    explicit Clock(size_t entries) : entries_(entries)
    {
        for (size_t i = 0; i < entries_.size(); ++i) {
            entries_[i].index = i;
        }
    }

    uint64_t now() const { return base_ + increment_; }
    uint64_t tick() const { return tick_; }
    Entry& entry(size_t i) { return entries_[i]; }
    size_t count() const { return entries_.size(); }

    void setClock(uint64_t timeOfDay)
    {
        base_ = timeOfDay - increment_;
        dayClock_.setBase(base_, tick_);
    }

    void armAt(size_t i, uint64_t timeOfDay)
    {
        Entry& e = entries_[i];
        (void)ticks_.cancel(e); // Unlinks it from either wheel.
        dayClock_.arm(e, timeOfDay, tick_);
        e.armed = true;
        e.firedAt = 0;
    }

    void cancel(size_t i)
    {
        (void)ticks_.cancel(entries_[i]);
        entries_[i].armed = false;
    }

    // One tick; checks that exactly the armed entries the time of day has
    // reached went off.
    void advance()
    {
        ++tick_;
        increment_ += kPeriod;
        std::vector<bool> due(entries_.size());
        for (const Entry& e : entries_) {
            due[e.index] = e.armed && e.timeOfDayNs <= now();
        }
        const auto expire = [this](Entry& e) {
            EXPECT_TRUE(e.armed) << "entry " << e.index << " went off twice";
            e.armed = false;
            e.firedAt = tick_;
        };
        dayClock_.advance(tick_, increment_, expire);
        ticks_.advance(tick_, expire);
        for (const Entry& e : entries_) {
            if (due[e.index]) {
                EXPECT_EQ(tick_, e.firedAt) << "entry " << e.index << " at " << e.timeOfDayNs << " now " << now();
            } else {
                EXPECT_TRUE(e.firedAt != tick_) << "entry " << e.index << " early: " << e.timeOfDayNs << " now " << now();
            }
        }
        EXPECT_EQ(ticks_.size() + dayClock_.size(), armedCount());
    }

    size_t armedCount() const
    {
        size_t armed = 0;
        for (const Entry& e : entries_) {
            armed += e.armed ? 1 : 0;
        }
        return armed;
    }

private:
    std::vector<Entry> entries_;
    TimeWheel<Entry, kSlots> ticks_;
    DayClockWheel<Entry, kSlots> dayClock_{kPeriod};
    uint64_t tick_ = 0;
    uint64_t increment_ = 0;
    uint64_t base_ = 0;
};

constexpr uint64_t k2024 = 1704067200ull * 1000000000ull;

TEST(DayClockWheel, GoesOffAtTheFirstTickAtOrAfterItsTime)
{
    Clock clock(6);
    clock.setClock(k2024 + 123456789);
    clock.armAt(0, clock.now() + 1);                 // within the current tick
    clock.armAt(1, clock.now() + kPeriod);           // exactly one tick on
    clock.armAt(2, clock.now() + kPeriod + 1);       // just after it
    clock.armAt(3, clock.now() + 40 * kPeriod - 1);  // revolutions ahead
    clock.armAt(4, clock.now() - 5);                 // past: due at once
    clock.armAt(5, clock.now());                     // now: due at once
    for (int i = 0; i < 45; ++i) {
        clock.advance();
    }
    EXPECT_EQ(0u, clock.armedCount());
    EXPECT_EQ(1u, clock.entry(0).firedAt);
    EXPECT_EQ(1u, clock.entry(1).firedAt);
    EXPECT_EQ(2u, clock.entry(2).firedAt);
    EXPECT_EQ(40u, clock.entry(3).firedAt);
    EXPECT_EQ(1u, clock.entry(4).firedAt);
    EXPECT_EQ(1u, clock.entry(5).firedAt);
}

TEST(DayClockWheel, SettingTheClockForwardFiresWhatItReaches)
{
    Clock clock(3);
    clock.setClock(k2024);
    clock.armAt(0, k2024 + 3600ull * 1000000000ull); // an hour on
    clock.armAt(1, k2024 + 7200ull * 1000000000ull); // two hours on
    clock.armAt(2, k2024 + 10 * kPeriod);
    clock.advance();
    clock.setClock(k2024 + 3601ull * 1000000000ull);
    clock.advance();
    EXPECT_EQ(2u, clock.entry(0).firedAt);
    EXPECT_EQ(2u, clock.entry(2).firedAt);
    EXPECT_TRUE(clock.entry(1).armed);
    for (int i = 0; i < 30; ++i) {
        clock.advance();
    }
    EXPECT_TRUE(clock.entry(1).armed);
}

TEST(DayClockWheel, SettingTheClockBackDelaysWhatItHasNotReached)
{
    Clock clock(2);
    clock.setClock(k2024);
    clock.armAt(0, k2024 + 5 * kPeriod);
    // Due at the next tick, set back before it comes.
    clock.armAt(1, k2024 - 1);
    clock.setClock(k2024 - 20 * kPeriod);
    for (int i = 0; i < 30; ++i) {
        clock.advance();
    }
    EXPECT_EQ(25u, clock.entry(0).firedAt);
    EXPECT_EQ(20u, clock.entry(1).firedAt);
}

TEST(DayClockWheel, ManyEntriesRandomArmsCancelsAndClockSettings)
{
    std::mt19937_64 random(12);
    for (int run = 0; run < 20; ++run) {
        Clock clock(2000);
        clock.setClock(k2024 + random() % 1000000000ull);
        for (int step = 0; step < 600; ++step) {
            const int action = static_cast<int>(random() % 100);
            if (action < 40) {
                // Arm one for a time from a little in the past to 60 ticks
                // on, often exactly on or near a tick's time.
                const size_t i = random() % clock.count();
                uint64_t at = clock.now() - 3 * kPeriod + random() % (63 * kPeriod);
                if (random() % 4 == 0) {
                    at = clock.now() + (random() % 60) * kPeriod + (random() % 3) - 1;
                }
                clock.armAt(i, at);
            } else if (action < 45) {
                clock.cancel(random() % clock.count());
            } else if (action < 50) {
                // Set the clock forward or back by a part of a tick, a few
                // ticks, more than a revolution, or days.
                const uint64_t amounts[] = {random() % kPeriod, (random() % 5) * kPeriod + random() % kPeriod,
                                            (kSlots + random() % 50) * kPeriod, (random() % 3) * 86400ull * 1000000000ull};
                const uint64_t amount = amounts[random() % 4];
                clock.setClock(random() % 2 == 0 ? clock.now() + amount : clock.now() - amount);
            } else {
                clock.advance();
            }
            if (::testing::Test::HasFailure()) {
                return;
            }
        }
    }
}

TEST(DayClockWheel, SettingTheClockTouchesNoEntry)
{
    // 4,096 alarms, then the clock set back and forth: setBase links and
    // unlinks nothing, so the entries on each wheel stay where they are.
    Clock clock(4096);
    clock.setClock(k2024);
    for (size_t i = 0; i < clock.count(); ++i) {
        clock.armAt(i, k2024 + 3600ull * 1000000000ull + i * kPeriod);
    }
    for (int i = 0; i < 100; ++i) {
        clock.setClock(k2024 + (i % 2 == 0 ? 1000 : 0));
    }
    clock.advance();
    EXPECT_EQ(4096u, clock.armedCount());
    clock.setClock(k2024 + 3600ull * 1000000000ull + 100 * kPeriod);
    clock.advance();
    // The tick after the setting is one period later still: 102 have gone off.
    EXPECT_EQ(4096u - 102u, clock.armedCount());
}

} // namespace
