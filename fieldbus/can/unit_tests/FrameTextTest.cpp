#include <can/FrameText.hpp>

#include <gtest/gtest.h>

#include <string>

namespace {

using can::CanFrame;
using can::FrameText;
using can::IdFormat;
using can::LinkError;

std::string formatted(const CanFrame& frame)
{
    char text[FrameText::kMaxFormattedLength + 1];
    const size_t n = FrameText::format(frame, text, sizeof text);
    return std::string(text, n);
}

TEST(FrameTextTest, ParsesCansendForms)
{
    const uint8_t deadbeef[] = {0xDE, 0xAD, 0xBE, 0xEF};
    EXPECT_EQ(FrameText::parse("123#DEADBEEF").value(), CanFrame::makeData(0x123, IdFormat::Standard, deadbeef, 4).value());
    EXPECT_EQ(FrameText::parse("123#deadbeef").value(), CanFrame::makeData(0x123, IdFormat::Standard, deadbeef, 4).value());
    EXPECT_EQ(FrameText::parse("1ABCDEF0#DE.AD.BE.EF").value(),
              CanFrame::makeData(0x1ABCDEF0, IdFormat::Extended, deadbeef, 4).value());
    EXPECT_EQ(FrameText::parse("00000123#").value(), CanFrame::makeData(0x123, IdFormat::Extended, nullptr, 0).value());
    EXPECT_EQ(FrameText::parse("7FF#R").value(), CanFrame::makeRemote(0x7FF, IdFormat::Standard, 0).value());
    EXPECT_EQ(FrameText::parse("7FF#R8").value(), CanFrame::makeRemote(0x7FF, IdFormat::Standard, 8).value());
    EXPECT_EQ(FrameText::parse("123#0102030405060708").value().length(), 8);
}

TEST(FrameTextTest, RefusesWhatIsNotAFrameWithTheReason)
{
    EXPECT_EQ(FrameText::parse("").error(), LinkError::InvalidHexDigit);
    EXPECT_EQ(FrameText::parse("123").error(), LinkError::InvalidHexDigit) << "no '#'";
    EXPECT_EQ(FrameText::parse("12#00").error(), LinkError::InvalidIdentifier) << "2 digits";
    EXPECT_EQ(FrameText::parse("1234#00").error(), LinkError::InvalidIdentifier) << "4 digits";
    EXPECT_EQ(FrameText::parse("123456789#00").error(), LinkError::InvalidIdentifier) << "9 digits";
    EXPECT_EQ(FrameText::parse("800#00").error(), LinkError::InvalidIdentifier) << "past 11 bits";
    EXPECT_EQ(FrameText::parse("20000000#00").error(), LinkError::InvalidIdentifier) << "past 29 bits";
    EXPECT_EQ(FrameText::parse("12G#00").error(), LinkError::InvalidHexDigit);
    EXPECT_EQ(FrameText::parse("123#0").error(), LinkError::InvalidDataLength) << "half a byte";
    EXPECT_EQ(FrameText::parse("123#0Z").error(), LinkError::InvalidHexDigit);
    EXPECT_EQ(FrameText::parse("123#010203040506070809").error(), LinkError::InvalidDataLength) << "9 bytes";
    EXPECT_EQ(FrameText::parse("123#01.02.03.04.05.06.07.08.09").error(), LinkError::InvalidDataLength);
    EXPECT_EQ(FrameText::parse("1ABCDEF0#01.02.03.04.05.06.07.08.").error(), LinkError::LineTooLong);
    EXPECT_EQ(FrameText::parse("123#..01").error(), LinkError::InvalidHexDigit);
    EXPECT_EQ(FrameText::parse("123#01.").error(), LinkError::InvalidHexDigit);
    EXPECT_EQ(FrameText::parse("123#R9").error(), LinkError::InvalidDataLength);
    EXPECT_EQ(FrameText::parse("123#R12").error(), LinkError::InvalidDataLength);
    EXPECT_EQ(FrameText::parse("123#RX").error(), LinkError::InvalidHexDigit);
    EXPECT_EQ(FrameText::parse(nullptr).error(), LinkError::InvalidHexDigit);
    const std::string huge(100000, 'A');
    EXPECT_EQ(FrameText::parse(huge.c_str()).error(), LinkError::LineTooLong);
}

TEST(FrameTextTest, FormatsCandumpColumns)
{
    const uint8_t bytes[] = {0x01, 0xAB, 0xFF};
    EXPECT_EQ(formatted(CanFrame::makeData(0x123, IdFormat::Standard, bytes, 3).value()), "123        [3]  01 AB FF");
    EXPECT_EQ(formatted(CanFrame::makeData(0x1ABCDEF0, IdFormat::Extended, bytes, 1).value()), "1ABCDEF0   [1]  01");
    EXPECT_EQ(formatted(CanFrame::makeData(0x5, IdFormat::Extended, nullptr, 0).value()), "00000005   [0] ");
    EXPECT_EQ(formatted(CanFrame::makeRemote(0x7FF, IdFormat::Standard, 4).value()), "7FF        [4]  remote request");
    char tiny[8];
    EXPECT_EQ(FrameText::format(CanFrame::makeData(0x123, IdFormat::Standard, bytes, 3).value(), tiny, sizeof tiny), 0u);
}

TEST(FrameTextTest, WhatFormatWritesParsesBackToTheSameFrame)
{
    const uint8_t bytes[] = {1, 2, 3, 4, 5, 6, 7, 8};
    for (const CanFrame& frame : {CanFrame::makeData(0x1FFFFFFF, IdFormat::Extended, bytes, 8).value(),
                                  CanFrame::makeData(0x000, IdFormat::Standard, bytes, 0).value(),
                                  CanFrame::makeData(0x42, IdFormat::Standard, bytes, 5).value()}) {
        // candump's columns back into cansend's form: identifier '#' bytes.
        const std::string text = formatted(frame);
        std::string send = text.substr(0, text.find(' ')) + "#";
        for (size_t at = text.find("]  "); at != std::string::npos && at + 3 < text.size(); at += 3) {
            send += text.substr(at + 3, 2);
        }
        EXPECT_EQ(FrameText::parse(send.c_str()).value(), frame) << send;
    }
}

} // namespace
