// Codes <-> microvolts at every gain (docs/iobus/mfio-register-map.md, "Analog scaling").
#include <iobus/AnalogScaling.hpp>

#include <gtest/gtest.h>

namespace {

using iobus::AnalogScaling;
using iobus::Gain;

constexpr Gain kGains[] = {Gain::X1, Gain::X10, Gain::X100, Gain::X1000};

TEST(AnalogScaling, FactorsAndTheirGains)
{
    EXPECT_EQ(AnalogScaling::factor(Gain::X1), 1u);
    EXPECT_EQ(AnalogScaling::factor(Gain::X10), 10u);
    EXPECT_EQ(AnalogScaling::factor(Gain::X100), 100u);
    EXPECT_EQ(AnalogScaling::factor(Gain::X1000), 1000u);
    for (const Gain gain : kGains) {
        EXPECT_EQ(AnalogScaling::fromFactor(AnalogScaling::factor(gain)).value(), gain);
    }
    EXPECT_EQ(AnalogScaling::fromFactor(0).status(), dcos::Status::InvalidArgument);
    EXPECT_EQ(AnalogScaling::fromFactor(50).status(), dcos::Status::InvalidArgument);
    EXPECT_EQ(AnalogScaling::fromFactor(10000).status(), dcos::Status::InvalidArgument);
}

TEST(AnalogScaling, FixedPointsOfTheMap)
{
    EXPECT_EQ(AnalogScaling::dacToMicrovolts(0x000), -10000000);
    EXPECT_EQ(AnalogScaling::dacToMicrovolts(0x800), 0);
    EXPECT_EQ(AnalogScaling::dacToMicrovolts(0xFFF), 9995117); // +9.9951 V
    EXPECT_EQ(AnalogScaling::adcToMicrovolts(3072, Gain::X1).microvolts, 5000000);
    EXPECT_EQ(AnalogScaling::adcToMicrovolts(3072, Gain::X10).microvolts, 500000);
    EXPECT_EQ(AnalogScaling::adcToMicrovolts(3072, Gain::X100).microvolts, 50000);
    EXPECT_EQ(AnalogScaling::adcToMicrovolts(3072, Gain::X1000).microvolts, 5000);
    EXPECT_EQ(AnalogScaling::adcToMicrovolts(2049, Gain::X1000).microvolts, 5); // 4.88 uV
    EXPECT_EQ(AnalogScaling::microvoltsToAdc(5000, Gain::X1000).code, 3072);
    EXPECT_EQ(AnalogScaling::microvoltsToAdc(-5000000, Gain::X1).code, 1024);
    EXPECT_EQ(AnalogScaling::inputRangeMicrovolts(Gain::X100), 100000);
}

TEST(AnalogScaling, EveryAdcCodeRoundTripsAtEveryGain)
{
    for (const Gain gain : kGains) {
        for (uint16_t code = 0; code <= 4095; ++code) {
            const auto value = AnalogScaling::adcToMicrovolts(code, gain);
            const auto back = AnalogScaling::microvoltsToAdc(value.microvolts, gain);
            ASSERT_EQ(back.code, code) << "gain x" << AnalogScaling::factor(gain);
            ASSERT_FALSE(back.saturated);
            ASSERT_EQ(value.overrange, code == 0 || code == 4095);
        }
    }
}

TEST(AnalogScaling, EveryDacCodeRoundTrips)
{
    for (uint16_t code = 0; code <= 4095; ++code) {
        const auto back = AnalogScaling::microvoltsToDac(AnalogScaling::dacToMicrovolts(code));
        ASSERT_EQ(back.code, code);
        ASSERT_FALSE(back.saturated);
    }
}

TEST(AnalogScaling, InputsBeyondFullScaleSaturateAtEveryGain)
{
    for (const Gain gain : kGains) {
        const int32_t range = AnalogScaling::inputRangeMicrovolts(gain);
        const auto high = AnalogScaling::microvoltsToAdc(range, gain);
        EXPECT_EQ(high.code, 4095);
        EXPECT_TRUE(high.saturated) << "+full scale is one step past 0xFFF";
        const auto low = AnalogScaling::microvoltsToAdc(-range - range / 100, gain);
        EXPECT_EQ(low.code, 0);
        EXPECT_TRUE(low.saturated);
        const auto inside = AnalogScaling::microvoltsToAdc(range / 2, gain);
        EXPECT_EQ(inside.code, 3072);
        EXPECT_FALSE(inside.saturated);
    }
    EXPECT_EQ(AnalogScaling::microvoltsToAdc(2147483647, Gain::X1000).code, 4095);
    EXPECT_EQ(AnalogScaling::microvoltsToDac(20000000).code, 4095);
    EXPECT_TRUE(AnalogScaling::microvoltsToDac(-20000000).saturated);
}

TEST(AnalogScaling, TheBoardsOverrangeFlagIsReported)
{
    const auto flagged = AnalogScaling::adcToMicrovolts(0x8000 | 0x7000 | 4095, Gain::X1);
    EXPECT_TRUE(flagged.overrange);
    EXPECT_EQ(flagged.microvolts, 9995117) << "the channel and flag bits do not change the value";
    EXPECT_FALSE(AnalogScaling::adcToMicrovolts(0x7000 | 2048, Gain::X1).overrange);
}

TEST(AnalogScaling, LoopbackIdealCodes)
{
    EXPECT_EQ(AnalogScaling::loopbackAdcCode(2049, Gain::X1000).code, 3048);
    EXPECT_EQ(AnalogScaling::loopbackAdcCode(2046, Gain::X1000).code, 48);
    EXPECT_EQ(AnalogScaling::loopbackAdcCode(2248, Gain::X10).code, 4048);
    EXPECT_TRUE(AnalogScaling::loopbackAdcCode(2051, Gain::X1000).saturated);
    EXPECT_EQ(AnalogScaling::loopbackAdcCode(100, Gain::X1).code, 100);
}

} // namespace
