#include <sja1000/BitTiming.hpp>
#include <sja1000/Sja1000Registers.hpp>

#include <gtest/gtest.h>

namespace {

using sja1000::BitTiming;
using sja1000::BitTimingCalculator;
using dcos::Status;

TEST(BitTimingTest, EveryCiaRateIsExactWithTheRecommendedSamplePoint)
{
    for (const uint32_t rate : sja1000::kCiaBitRates) {
        const dcos::Result<BitTiming> timing = BitTimingCalculator::forBitRate(rate);
        ASSERT_TRUE(timing.ok()) << rate;
        const BitTiming& t = timing.value();
        // Decoding what would be written gives the same rate back, exactly.
        const dcos::Result<BitTiming> decoded = BitTimingCalculator::decode(t.btr0, t.btr1);
        ASSERT_TRUE(decoded.ok()) << rate;
        EXPECT_EQ(decoded.value().bitRate, rate);
        EXPECT_EQ(decoded.value().samplePointPermille, t.samplePointPermille);
        // Within 2.5 % of the CiA's point (whole quanta cannot always hit it).
        const int error = int{t.samplePointPermille} - int{BitTimingCalculator::recommendedSamplePoint(rate)};
        EXPECT_LE(error < 0 ? -error : error, 25) << rate;
        EXPECT_GE(t.quantaPerBit, BitTimingCalculator::kMinQuantaPerBit) << rate;
        EXPECT_LE(t.jumpWidth, t.segment2) << rate;
        EXPECT_EQ(t.quantaPerBit, 1 + t.segment1 + t.segment2) << rate;
    }
}

TEST(BitTimingTest, OneMegabitOnSixteenMegahertzIsTheClassicSetting)
{
    // 8 quanta of 125 ns, sampled at 75 %: BTR0 0x40 (SJW 2), BTR1 0x14, as
    // the well-known tables for a 16 MHz SJA1000 give.
    const dcos::Result<BitTiming> timing = BitTimingCalculator::forBitRate(1'000'000);
    ASSERT_TRUE(timing.ok());
    EXPECT_EQ(timing.value().btr1, 0x14);
    EXPECT_EQ(timing.value().btr0 & sja1000::reg::kBtr0PrescalerMask, 0);
    EXPECT_EQ(timing.value().samplePointPermille, 750);
}

TEST(BitTimingTest, FiveHundredKilobitSamplesAtEightySevenAndAHalfPercent)
{
    const dcos::Result<BitTiming> timing = BitTimingCalculator::forBitRate(500'000);
    ASSERT_TRUE(timing.ok());
    EXPECT_EQ(timing.value().quantaPerBit, 16);
    EXPECT_EQ(timing.value().samplePointPermille, 875);
    EXPECT_EQ(timing.value().segment1, 13);
    EXPECT_EQ(timing.value().segment2, 2);
}

TEST(BitTimingTest, RatesThatCannotBeMetExactlyAreRefused)
{
    EXPECT_EQ(BitTimingCalculator::forBitRate(0).status(), Status::InvalidArgument);
    EXPECT_EQ(BitTimingCalculator::forBitRate(2'000'000).status(), Status::InvalidArgument) << "above the chip";
    EXPECT_EQ(BitTimingCalculator::forBitRate(333'333).status(), Status::InvalidArgument) << "not a divisor";
    EXPECT_EQ(BitTimingCalculator::forBitRate(1'000).status(), Status::InvalidArgument) << "prescaler too large";
    EXPECT_EQ(BitTimingCalculator::forBitRate(125'000, 0).status(), Status::InvalidArgument);
    // 83.333 kbit/s has no whole quantum count at 16 MHz; 100 kbit/s has.
    EXPECT_EQ(BitTimingCalculator::forBitRate(83'333).status(), Status::InvalidArgument);
    EXPECT_TRUE(BitTimingCalculator::forBitRate(100'000).ok());
}

TEST(BitTimingTest, DecodeReadsTheFieldsAndRefusesFractionalRates)
{
    // BRP 1 (prescaler 2), SJW 1, TSEG1 13, TSEG2 2: 16 quanta of 250 ns = 250 kbit/s.
    const dcos::Result<BitTiming> decoded = BitTimingCalculator::decode(0x01, 0x1C);
    ASSERT_TRUE(decoded.ok());
    EXPECT_EQ(decoded.value().bitRate, 250'000u);
    EXPECT_EQ(decoded.value().prescaler, 2);
    EXPECT_EQ(decoded.value().segment1, 13);
    EXPECT_EQ(decoded.value().segment2, 2);
    EXPECT_EQ(decoded.value().jumpWidth, 1);
    EXPECT_EQ(decoded.value().samplePointPermille, 875);
    // 16 MHz / (2 * 1 * 24 quanta) is not a whole number of bit/s; 25 quanta are (320 kbit/s).
    EXPECT_EQ(BitTimingCalculator::decode(0x00, 0x7E).status(), Status::InvalidArgument);
    EXPECT_EQ(BitTimingCalculator::decode(0x00, 0x7F).value().bitRate, 320'000u);
}

} // namespace
