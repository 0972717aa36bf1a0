// CanFrame: valid by construction, every refusal with its reason.
#include <can/CanFrame.hpp>

#include <gtest/gtest.h>

namespace {

using can::CanFrame;
using can::IdFormat;
using can::LinkError;

constexpr uint8_t kBytes[8] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};

TEST(CanFrame, DefaultIsAnEmptyStandardDataFrame)
{
    const CanFrame frame;
    EXPECT_EQ(frame.id(), 0u);
    EXPECT_EQ(frame.format(), IdFormat::Standard);
    EXPECT_FALSE(frame.isRemote());
    EXPECT_EQ(frame.length(), 0);
}

TEST(CanFrame, DataFrameKeepsItsFieldsAndZeroesTheRest)
{
    const auto frame = CanFrame::makeData(0x123, IdFormat::Standard, kBytes, 3);
    ASSERT_TRUE(frame.ok());
    EXPECT_EQ(frame.value().id(), 0x123u);
    EXPECT_FALSE(frame.value().isExtended());
    EXPECT_FALSE(frame.value().isRemote());
    EXPECT_EQ(frame.value().length(), 3);
    EXPECT_EQ(frame.value().byte(0), 0x11);
    EXPECT_EQ(frame.value().byte(2), 0x33);
    for (size_t i = 3; i < CanFrame::kMaxDataLength; ++i) {
        EXPECT_EQ(frame.value().data()[i], 0) << "byte " << i;
    }
    EXPECT_EQ(frame.value().byte(8), 0);
    EXPECT_EQ(frame.value().byte(1000), 0);
}

TEST(CanFrame, IdentifierLimitsOfBothFormats)
{
    EXPECT_TRUE(CanFrame::makeData(0x7FF, IdFormat::Standard, kBytes, 0).ok());
    EXPECT_EQ(CanFrame::makeData(0x800, IdFormat::Standard, kBytes, 0).error(), LinkError::InvalidIdentifier);
    EXPECT_TRUE(CanFrame::makeData(0x800, IdFormat::Extended, kBytes, 0).ok());
    EXPECT_TRUE(CanFrame::makeData(0x1FFFFFFF, IdFormat::Extended, kBytes, 0).ok());
    EXPECT_EQ(CanFrame::makeData(0x20000000, IdFormat::Extended, kBytes, 0).error(), LinkError::InvalidIdentifier);
    EXPECT_EQ(CanFrame::makeData(0xFFFFFFFF, IdFormat::Extended, kBytes, 0).error(), LinkError::InvalidIdentifier);
    EXPECT_EQ(CanFrame::makeRemote(0x800, IdFormat::Standard, 0).error(), LinkError::InvalidIdentifier);
    EXPECT_EQ(CanFrame::makeRemote(0x20000000, IdFormat::Extended, 0).error(), LinkError::InvalidIdentifier);
    EXPECT_EQ(CanFrame::maxId(IdFormat::Standard), 0x7FFu);
    EXPECT_EQ(CanFrame::maxId(IdFormat::Extended), 0x1FFFFFFFu);
}

TEST(CanFrame, DataLengthAboveEightIsRefused)
{
    EXPECT_TRUE(CanFrame::makeData(1, IdFormat::Standard, kBytes, 8).ok());
    for (uint8_t length = 9; length != 0; ++length) {
        ASSERT_EQ(CanFrame::makeData(1, IdFormat::Standard, kBytes, length).error(), LinkError::InvalidDataLength)
            << int(length);
        ASSERT_EQ(CanFrame::makeRemote(1, IdFormat::Extended, length).error(), LinkError::InvalidDataLength)
            << int(length);
    }
}

TEST(CanFrame, CheckNamesTheFirstProblem)
{
    EXPECT_EQ(CanFrame::check(0x7FF, IdFormat::Standard, 8), LinkError::Ok);
    EXPECT_EQ(CanFrame::check(0x800, IdFormat::Standard, 9), LinkError::InvalidIdentifier);
    EXPECT_EQ(CanFrame::check(0x7FF, IdFormat::Standard, 9), LinkError::InvalidDataLength);
}

TEST(CanFrame, MissingBytesAreRefusedUnlessThereAreNone)
{
    EXPECT_EQ(CanFrame::makeData(1, IdFormat::Standard, nullptr, 1).error(), LinkError::InvalidArgument);
    EXPECT_TRUE(CanFrame::makeData(1, IdFormat::Standard, nullptr, 0).ok());
}

TEST(CanFrame, RemoteFrameCarriesALengthButNoData)
{
    const auto frame = CanFrame::makeRemote(0x1ABCDEF0, IdFormat::Extended, 5);
    ASSERT_TRUE(frame.ok());
    EXPECT_TRUE(frame.value().isRemote());
    EXPECT_TRUE(frame.value().isExtended());
    EXPECT_EQ(frame.value().length(), 5);
    for (size_t i = 0; i < CanFrame::kMaxDataLength; ++i) {
        EXPECT_EQ(frame.value().byte(i), 0);
    }
}

TEST(CanFrame, EqualityComparesEveryField)
{
    const CanFrame base = CanFrame::makeData(0x100, IdFormat::Standard, kBytes, 4).value();
    EXPECT_EQ(base, CanFrame::makeData(0x100, IdFormat::Standard, kBytes, 4).value());
    EXPECT_FALSE(base == CanFrame::makeData(0x101, IdFormat::Standard, kBytes, 4).value());
    EXPECT_FALSE(base == CanFrame::makeData(0x100, IdFormat::Extended, kBytes, 4).value());
    EXPECT_FALSE(base == CanFrame::makeData(0x100, IdFormat::Standard, kBytes, 3).value());
    EXPECT_FALSE(base == CanFrame::makeRemote(0x100, IdFormat::Standard, 4).value());
    const uint8_t other[4] = {0x11, 0x22, 0x33, 0x45};
    EXPECT_FALSE(base == CanFrame::makeData(0x100, IdFormat::Standard, other, 4).value());
}

} // namespace
