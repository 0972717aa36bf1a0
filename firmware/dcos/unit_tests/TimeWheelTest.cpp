// Host tests for the timer agent's time wheel (dissertation 7.5, Fig. 7.9).
#include <dcos/internal/TimeWheel.hpp>

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <vector>

using dcos::Status;
using dcos::internal::isPrime;
using dcos::internal::TimeWheel;
using dcos::internal::TimeWheelNode;

namespace {

struct Timer : TimeWheelNode<> {
    int id = 0;
    uint64_t due = 0;
};

constexpr size_t kSlots = 7;
using Wheel = TimeWheel<Timer, kSlots>;

// Advances one tick at a time and records at which tick each timer fired.
std::map<int, uint64_t> runUntil(Wheel& wheel, uint64_t from, uint64_t to)
{
    std::map<int, uint64_t> fired;
    for (uint64_t tick = from; tick <= to; ++tick) {
        wheel.advance(tick, [&](Timer& timer) { fired[timer.id] = tick; });
    }
    return fired;
}

} // namespace

TEST(TimeWheelTest, PrimeCheck)
{
    EXPECT_FALSE(isPrime(0));
    EXPECT_FALSE(isPrime(1));
    EXPECT_TRUE(isPrime(2));
    EXPECT_TRUE(isPrime(7));
    EXPECT_FALSE(isPrime(9));
    EXPECT_TRUE(isPrime(251));
    EXPECT_FALSE(isPrime(256));
    EXPECT_EQ(Wheel::slotCount(), 7u);
    EXPECT_EQ(Wheel::slotOf(15), 1u);
}

TEST(TimeWheelTest, FiresExactlyAtTheDueTickNotEarlierNorLater)
{
    Wheel wheel;
    Timer timer;
    timer.id = 1;
    ASSERT_EQ(wheel.insert(timer, 5), Status::Ok);
    for (uint64_t tick = 1; tick < 5; ++tick) {
        EXPECT_EQ(wheel.popExpired(tick), nullptr) << "tick " << tick;
    }
    EXPECT_EQ(wheel.popExpired(5), &timer);
    EXPECT_EQ(wheel.popExpired(5), nullptr);
    EXPECT_EQ(wheel.size(), 0u);
    EXPECT_FALSE(timer.isLinked());
}

TEST(TimeWheelTest, WrapsAroundTheSlotIndex)
{
    Wheel wheel(10);
    Timer a, b;
    a.id = 1;
    b.id = 2;
    // From tick 10 (slot 3), tick 15 is slot 1 and tick 17 is slot 3 again.
    ASSERT_EQ(wheel.insert(a, 15), Status::Ok);
    ASSERT_EQ(wheel.insert(b, 17), Status::Ok);
    const auto fired = runUntil(wheel, 11, 30);
    EXPECT_EQ(fired.at(1), 15u);
    EXPECT_EQ(fired.at(2), 17u);
    EXPECT_EQ(wheel.currentTick(), 30u);
}

TEST(TimeWheelTest, ManyTimersInOneSlotStaySortedAndFireInTheirOwnRevolution)
{
    Wheel wheel;
    Timer timers[5];
    // All share slot 3; inserted out of order, the last one revolutions ahead.
    const uint64_t dues[5] = {24, 3, 10, 3 + 7 * 20, 17};
    for (int i = 0; i < 5; ++i) {
        timers[i].id = i;
        ASSERT_EQ(wheel.insert(timers[i], dues[i]), Status::Ok);
    }
    EXPECT_EQ(wheel.size(), 5u);
    const auto fired = runUntil(wheel, 1, 200);
    for (int i = 0; i < 5; ++i) {
        EXPECT_EQ(fired.at(i), dues[i]) << "timer " << i;
    }
}

TEST(TimeWheelTest, SameDueTickFiresInInsertionOrder)
{
    Wheel wheel;
    Timer timers[3];
    for (int i = 0; i < 3; ++i) {
        timers[i].id = i;
        ASSERT_EQ(wheel.insert(timers[i], 9), Status::Ok);
    }
    std::vector<int> order;
    wheel.advance(9, [&](Timer& timer) { order.push_back(timer.id); });
    EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
}

TEST(TimeWheelTest, PastAndPresentDueTicksFireOnTheNextAdvance)
{
    Wheel wheel(100);
    Timer past, now;
    past.id = 1;
    now.id = 2;
    ASSERT_EQ(wheel.insert(past, 3), Status::Ok);
    ASSERT_EQ(wheel.insert(now, 100), Status::Ok);
    std::vector<int> order;
    EXPECT_EQ(wheel.advance(100, [&](Timer& timer) { order.push_back(timer.id); }), 2u);
    EXPECT_EQ(order, (std::vector<int>{1, 2}));
}

TEST(TimeWheelTest, CancelDisarms)
{
    Wheel wheel;
    Timer a, b;
    a.id = 1;
    b.id = 2;
    ASSERT_EQ(wheel.insert(a, 4), Status::Ok);
    ASSERT_EQ(wheel.insert(b, 4), Status::Ok);
    EXPECT_EQ(wheel.insert(a, 6), Status::InvalidArgument);
    EXPECT_EQ(wheel.cancel(a), Status::Ok);
    EXPECT_EQ(wheel.cancel(a), Status::NotFound);
    EXPECT_EQ(wheel.size(), 1u);
    const auto fired = runUntil(wheel, 1, 20);
    EXPECT_EQ(fired.count(1), 0u);
    EXPECT_EQ(fired.at(2), 4u);
    // A cancelled timer can be re-armed.
    ASSERT_EQ(wheel.insert(a, 25), Status::Ok);
    EXPECT_EQ(runUntil(wheel, 21, 30).at(1), 25u);
}

TEST(TimeWheelTest, CallbackMayRearmForPeriodicAlarms)
{
    Wheel wheel;
    Timer periodic;
    periodic.id = 1;
    ASSERT_EQ(wheel.insert(periodic, 3), Status::Ok);
    std::vector<uint64_t> firings;
    for (uint64_t tick = 1; tick <= 40; ++tick) {
        wheel.advance(tick, [&](Timer& timer) {
            firings.push_back(tick);
            ASSERT_EQ(wheel.insert(timer, tick + 10), Status::Ok);
        });
    }
    EXPECT_EQ(firings, (std::vector<uint64_t>{3, 13, 23, 33}));
}

TEST(TimeWheelTest, LargeJumpCatchesUpWithoutLosingTimers)
{
    TimeWheel<Timer, 13> wheel;
    Timer timers[40];
    for (int i = 0; i < 40; ++i) {
        timers[i].id = i;
        ASSERT_EQ(wheel.insert(timers[i], static_cast<uint64_t>(i) * 37 + 1), Status::Ok);
    }
    // Jump far past half of them in one call: exactly the due ones fire.
    std::map<int, bool> fired;
    wheel.advance(740, [&](Timer& timer) { fired[timer.id] = true; });
    for (int i = 0; i < 40; ++i) {
        EXPECT_EQ(fired.count(i) == 1, static_cast<uint64_t>(i) * 37 + 1 <= 740) << "timer " << i;
    }
    EXPECT_EQ(wheel.currentTick(), 740u);
    // The rest still fire exactly on time afterwards.
    for (uint64_t tick = 741; tick <= 1500; ++tick) {
        wheel.advance(tick, [&](Timer& timer) {
            EXPECT_EQ(static_cast<uint64_t>(timer.id) * 37 + 1, tick);
            fired[timer.id] = true;
        });
    }
    EXPECT_EQ(fired.size(), 40u);
    EXPECT_EQ(wheel.size(), 0u);
}

TEST(TimeWheelTest, HugeJumpCostsAtMostOneRevolution)
{
    // Without the skip to the last revolution this would visit 2^40 ticks and hang.
    Wheel wheel;
    Timer early, late;
    early.id = 1;
    late.id = 2;
    ASSERT_EQ(wheel.insert(early, 12345), Status::Ok);
    ASSERT_EQ(wheel.insert(late, (uint64_t{1} << 40) + 1), Status::Ok);
    std::vector<int> fired;
    wheel.advance(uint64_t{1} << 40, [&](Timer& timer) { fired.push_back(timer.id); });
    EXPECT_EQ(fired, (std::vector<int>{1}));
    wheel.advance((uint64_t{1} << 40) + 1, [&](Timer& timer) { fired.push_back(timer.id); });
    EXPECT_EQ(fired, (std::vector<int>{1, 2}));
}

TEST(TimeWheelTest, RandomTimersFireExactlyOnTimeAgainstReference)
{
    TimeWheel<Timer, 11> wheel(1000);
    Timer timers[100];
    std::mt19937_64 random(7);
    std::vector<bool> armed(100, false);
    for (uint64_t tick = 1001; tick <= 4000; ++tick) {
        const int i = static_cast<int>(random() % 100);
        if (!armed[i]) {
            timers[i].id = i;
            timers[i].due = tick + random() % 200;
            ASSERT_EQ(wheel.insert(timers[i], timers[i].due), Status::Ok);
            armed[i] = true;
        } else if (random() % 4 == 0) {
            ASSERT_EQ(wheel.cancel(timers[i]), Status::Ok);
            armed[i] = false;
        }
        wheel.advance(tick, [&](Timer& timer) {
            EXPECT_EQ(timer.due, tick) << "timer " << timer.id;
            armed[timer.id] = false;
        });
        for (int j = 0; j < 100; ++j) {
            ASSERT_EQ(armed[j], timers[j].isLinked());
        }
    }
}
