// bsp::nanosecondsIntoTick, the part of every uptime finer than a tick: the
// 8254's count, and whether the tick it ended is still to be counted.
#include <bsp/Board.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

// Board486.cpp, which defines it on the board, is not part of host builds.
uint32_t bsp::tickTimerDivisor = 0;

namespace {

constexpr uint32_t kDivisor = 1193; // 1 kHz
constexpr uint32_t kTickNs = 999'847;

// Queues what the 8254's counter 0 (low, high) and the master 8259's request
// register read, then reads.
uint32_t readWith(uint32_t count, bool tickRequested)
{
    port_io_mock::reset();
    bsp::tickTimerDivisor = kDivisor;
    port_io_mock::queueRead(0x40, static_cast<uint8_t>(count));
    port_io_mock::queueRead(0x40, static_cast<uint8_t>(count >> 8));
    port_io_mock::queueRead(0x20, tickRequested ? 0x01 : 0x00);
    return bsp::nanosecondsIntoTick();
}

TEST(NanosecondsIntoTick, CountsDownFromTheDivisor)
{
    EXPECT_EQ(readWith(kDivisor - 1, false), 838u);
    EXPECT_EQ(readWith(kDivisor / 2, false), (kDivisor - kDivisor / 2) * 26819u >> 5);
    EXPECT_EQ(readWith(1, false), (kDivisor - 1) * 26819u >> 5);
}

TEST(NanosecondsIntoTick, APendingTickAddsAWholePeriod)
{
    EXPECT_EQ(readWith(kDivisor - 1, true), (kDivisor + 1) * 26819u >> 5);
    // Only in the first half of a period is a request taken for the reload
    // just passed: interrupts are never held off for half a tick.
    EXPECT_EQ(readWith(10, true), (kDivisor - 10) * 26819u >> 5);
}

TEST(NanosecondsIntoTick, TheFirstCountAfterTheReloadIsAWholePeriodWithOrWithoutARequest)
{
    // QEMU's 8254 raises the tick's request one count after the reload: a
    // read in between sees the reloaded count and no request. The period
    // has ended either way and the tick's handler cannot have run yet.
    EXPECT_EQ(readWith(kDivisor, false), kDivisor * 26819u >> 5);
    EXPECT_EQ(readWith(kDivisor, true), kDivisor * 26819u >> 5);
    // That is the tick's length, to the scaling's rounding.
    EXPECT_NEAR(static_cast<double>(readWith(kDivisor, false)), kTickNs, 3.0);
}

TEST(NanosecondsIntoTick, ReadsZeroBeforeTheTickStarts)
{
    port_io_mock::reset();
    bsp::tickTimerDivisor = 0;
    port_io_mock::queueRead(0x40, 0);
    port_io_mock::queueRead(0x40, 0);
    port_io_mock::queueRead(0x20, 0);
    EXPECT_EQ(bsp::nanosecondsIntoTick(), 0u);
}

} // namespace
