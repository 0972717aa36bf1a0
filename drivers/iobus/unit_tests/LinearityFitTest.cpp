// The bring-up's integer fit: offset, gain error, maximum error and noise.
#include <iobus/LinearityFit.hpp>

#include <gtest/gtest.h>

namespace {

using iobus::LinearityFit;

// Nine points over the converter's range at gain 1, each read eight times
// as ideal + error(u) + the given noise pattern.
template <typename Error>
void fill(LinearityFit& fit, Error error, int noise = 0)
{
    fit.clear();
    for (int step = -4; step <= 4; ++step) {
        const int ideal = 2048 + step * 500;
        fit.beginPoint(static_cast<uint16_t>(ideal), ideal);
        for (int sample = 0; sample < 8; ++sample) {
            const int wobble = noise == 0 ? 0 : ((sample & 1) != 0 ? noise : -noise);
            fit.addSample(static_cast<uint16_t>(ideal + error(ideal - 2048) + wobble));
        }
    }
}

TEST(LinearityFit, AnIdealBoardHasNoErrors)
{
    LinearityFit fit;
    fill(fit, [](int) { return 0; });
    EXPECT_EQ(fit.count(), 9u);
    EXPECT_EQ(fit.offsetHundredths(), 0);
    EXPECT_EQ(fit.gainErrorHundredthsPercent(), 0);
    EXPECT_EQ(fit.maximumErrorHundredths(), 0);
    EXPECT_EQ(fit.noiseHundredths(), 0);
    EXPECT_EQ(fit.meanTenths(0), 480);
    EXPECT_EQ(fit.meanTenths(8), 40480);
    EXPECT_EQ(fit.idealSpan(), 4000);
    EXPECT_EQ(fit.measuredSpanHundredths(), 400000);
}

TEST(LinearityFit, OffsetAndGainAreSeparated)
{
    LinearityFit fit;
    fill(fit, [](int u) { return 3 + u / 100; }); // +3 LSB offset, +1 % gain
    EXPECT_EQ(fit.offsetHundredths(), 300);
    EXPECT_EQ(fit.gainErrorHundredthsPercent(), 100);
    EXPECT_EQ(fit.maximumErrorHundredths(), 2300); // 3 + 2000 / 100 at the top
    fill(fit, [](int u) { return -u / 250; });     // -0.4 % gain
    EXPECT_EQ(fit.offsetHundredths(), 0);
    EXPECT_EQ(fit.gainErrorHundredthsPercent(), -40);
}

TEST(LinearityFit, NoiseIsTheLargestSampleStandardDeviation)
{
    LinearityFit fit;
    fill(fit, [](int) { return 0; }, 1);
    // Eight samples of +-1: variance 8 / 7, deviation 1.069.
    EXPECT_EQ(fit.noiseHundredths(), 106);
    EXPECT_EQ(fit.offsetHundredths(), 0);
}

TEST(LinearityFit, ADeadInputHasNoSpan)
{
    LinearityFit fit;
    fit.clear();
    for (int step = 0; step < 5; ++step) {
        fit.beginPoint(static_cast<uint16_t>(2046 + step), 48 + 1000 * step);
        fit.addSample(2048);
    }
    EXPECT_EQ(fit.measuredSpanHundredths(), 0);
    EXPECT_EQ(fit.idealSpan(), 4000);
    EXPECT_EQ(fit.gainErrorHundredthsPercent(), -10000);
}

TEST(LinearityFit, FullFitAndSquareRoots)
{
    LinearityFit fit;
    for (size_t i = 0; i < LinearityFit::kMaximumPoints; ++i) {
        EXPECT_TRUE(fit.beginPoint(0, 0));
    }
    EXPECT_FALSE(fit.beginPoint(0, 0));
    EXPECT_EQ(iobus::integerSquareRoot(0), 0u);
    EXPECT_EQ(iobus::integerSquareRoot(15), 3u);
    EXPECT_EQ(iobus::integerSquareRoot(16), 4u);
    EXPECT_EQ(iobus::integerSquareRoot(~uint64_t{0}), 0xFFFFFFFFu);
}

} // namespace
