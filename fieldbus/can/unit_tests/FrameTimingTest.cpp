#include <can/FrameTiming.hpp>

#include <gtest/gtest.h>

namespace {

using can::CanFrame;
using can::IdFormat;

TEST(FrameTimingTest, TheWorstCaseLengthsOfTheLiterature)
{
    const uint8_t bytes[8] = {};
    // Davis et al. 2007: 135 bits for 8 bytes standard, 160 extended; 55 and 80 empty.
    EXPECT_EQ(can::frameBits(CanFrame::makeData(0x123, IdFormat::Standard, bytes, 8).value()), 135u);
    EXPECT_EQ(can::frameBits(CanFrame::makeData(0x123, IdFormat::Extended, bytes, 8).value()), 160u);
    EXPECT_EQ(can::frameBits(CanFrame::makeData(0x123, IdFormat::Standard, bytes, 0).value()), 55u);
    EXPECT_EQ(can::frameBits(CanFrame::makeData(0x123, IdFormat::Extended, bytes, 0).value()), 80u);
    // A remote frame carries no data, whatever its length code asks for.
    EXPECT_EQ(can::frameBits(CanFrame::makeRemote(0x123, IdFormat::Extended, 8).value()), 80u);
}

TEST(FrameTimingTest, NanosecondsFollowTheBitRate)
{
    const uint8_t bytes[8] = {};
    const CanFrame full = CanFrame::makeData(0x1, IdFormat::Extended, bytes, 8).value();
    EXPECT_EQ(can::frameNanoseconds(full, 1'000'000), 160'000u);
    EXPECT_EQ(can::frameNanoseconds(full, 125'000), 1'280'000u);
    EXPECT_EQ(can::frameNanoseconds(full, 0), 0u);
    // At 1 Mbit/s: 6,250 full extended frames a second, 7,407 full standard ones.
    EXPECT_EQ(1'000'000'000u / can::frameNanoseconds(full, 1'000'000), 6'250u);
    const CanFrame standard = CanFrame::makeData(0x1, IdFormat::Standard, bytes, 8).value();
    EXPECT_EQ(1'000'000'000u / can::frameNanoseconds(standard, 1'000'000), 7'407u);
}

} // namespace
