// RtuTiming: t1.5 and t3.5 computed below 19200 baud and fixed above.
#include <modbus/RtuTiming.hpp>

#include <gtest/gtest.h>

namespace {

using modbus::ModbusError;
using modbus::RtuTiming;

TEST(RtuTimingTest, ComputedAt9600Baud)
{
    // 11 bits at 9600 baud: 1145833.3 ns per character, rounded up.
    const auto timing = RtuTiming::make(9600);
    ASSERT_TRUE(timing.ok());
    EXPECT_EQ(timing.value().characterNs, 1145834u);
    EXPECT_EQ(timing.value().t15Ns, 1718750u);
    EXPECT_EQ(timing.value().t35Ns, 4010417u);
}

TEST(RtuTimingTest, At19200BaudStillComputed)
{
    const auto timing = RtuTiming::make(19200);
    ASSERT_TRUE(timing.ok());
    EXPECT_EQ(timing.value().characterNs, 572917u);
    EXPECT_EQ(timing.value().t15Ns, 859375u);
    EXPECT_EQ(timing.value().t35Ns, 2005209u);
    // The default timing is this one, the default line of [SL] 2.5.1.
    const RtuTiming defaults;
    EXPECT_EQ(defaults.characterNs, timing.value().characterNs);
    EXPECT_EQ(defaults.t15Ns, timing.value().t15Ns);
    EXPECT_EQ(defaults.t35Ns, timing.value().t35Ns);
}

TEST(RtuTimingTest, FixedAbove19200Baud)
{
    for (uint32_t baud : {19201u, 38400u, 57600u, 115200u}) {
        const auto timing = RtuTiming::make(baud);
        ASSERT_TRUE(timing.ok()) << baud;
        EXPECT_EQ(timing.value().t15Ns, 750000u) << baud;
        EXPECT_EQ(timing.value().t35Ns, 1750000u) << baud;
    }
    EXPECT_EQ(RtuTiming::make(115200).value().characterNs, 95487u);
}

TEST(RtuTimingTest, TenBitCharactersAreShorter)
{
    const auto timing = RtuTiming::make(9600, 10);
    ASSERT_TRUE(timing.ok());
    EXPECT_EQ(timing.value().characterNs, 1041667u);
    EXPECT_EQ(timing.value().t35Ns, 3645834u);
}

TEST(RtuTimingTest, RefusesOutOfRange)
{
    EXPECT_EQ(RtuTiming::make(0).error(), ModbusError::InvalidConfiguration);
    EXPECT_EQ(RtuTiming::make(299).error(), ModbusError::InvalidConfiguration);
    EXPECT_EQ(RtuTiming::make(4000001).error(), ModbusError::InvalidConfiguration);
    EXPECT_EQ(RtuTiming::make(9600, 9).error(), ModbusError::InvalidConfiguration);
    EXPECT_EQ(RtuTiming::make(9600, 13).error(), ModbusError::InvalidConfiguration);
    EXPECT_TRUE(RtuTiming::make(300).ok());
    EXPECT_TRUE(RtuTiming::make(4000000, 12).ok());
}

} // namespace
