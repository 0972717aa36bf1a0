// SlcanCodec: exact lines as CANable, USBtin and Linux's slcan write them,
// every malformed line counted, and parsing that always recovers.
#include <can/SlcanCodec.hpp>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using can::CanFrame;
using can::IdFormat;
using can::LinkError;
using can::SlcanCodec;
using can::SlcanMessage;
using can::SlcanMessageKind;

struct Fed {
    std::vector<SlcanMessage> messages;
    std::vector<LinkError> rejections;
};

Fed feed(SlcanCodec& codec, const std::string& text)
{
    Fed fed;
    for (const char character : text) {
        switch (codec.feed(static_cast<uint8_t>(character))) {
        case SlcanCodec::Outcome::Pending: break;
        case SlcanCodec::Outcome::Message: fed.messages.push_back(codec.message()); break;
        case SlcanCodec::Outcome::Rejected: fed.rejections.push_back(codec.lastError()); break;
        }
    }
    return fed;
}

// The one message a line decodes to; fails the test if it does not.
SlcanMessage decode(const std::string& text)
{
    SlcanCodec codec;
    const Fed fed = feed(codec, text);
    EXPECT_EQ(fed.messages.size(), 1u) << text;
    EXPECT_TRUE(fed.rejections.empty()) << text;
    return fed.messages.empty() ? SlcanMessage() : fed.messages.front();
}

// Why a line is refused.
LinkError refusal(const std::string& text)
{
    SlcanCodec codec;
    const Fed fed = feed(codec, text);
    EXPECT_TRUE(fed.messages.empty()) << text;
    EXPECT_EQ(fed.rejections.size(), 1u) << text;
    EXPECT_EQ(codec.statistics().rejected, 1u);
    return fed.rejections.empty() ? LinkError::Ok : fed.rejections.front();
}

std::string format(const SlcanMessage& message)
{
    char line[64];
    const auto written = SlcanCodec::format(message, line, sizeof(line));
    EXPECT_TRUE(written.ok()) << can::linkErrorName(written.error());
    return std::string(line, written.ok() ? written.value() : 0);
}

SlcanMessage frameMessage(const CanFrame& frame)
{
    SlcanMessage message;
    message.kind = SlcanMessageKind::Frame;
    message.frame = frame;
    return message;
}

TEST(SlcanCodec, StandardDataFrame)
{
    const SlcanMessage message = decode("t123411223344\r");
    ASSERT_EQ(message.kind, SlcanMessageKind::Frame);
    EXPECT_EQ(message.frame.id(), 0x123u);
    EXPECT_FALSE(message.frame.isExtended());
    EXPECT_FALSE(message.frame.isRemote());
    EXPECT_EQ(message.frame.length(), 4);
    EXPECT_EQ(std::vector<uint8_t>(message.frame.data(), message.frame.data() + 4),
              (std::vector<uint8_t>{0x11, 0x22, 0x33, 0x44}));
    EXPECT_FALSE(message.hasTimestamp);
}

TEST(SlcanCodec, ExtendedDataFrame)
{
    // Eight identifier digits: "1ABCDEF0", then DLC 2, then 01 02.
    const SlcanMessage message = decode("T1ABCDEF020102\r");
    ASSERT_EQ(message.kind, SlcanMessageKind::Frame);
    EXPECT_EQ(message.frame.id(), 0x1ABCDEF0u);
    EXPECT_TRUE(message.frame.isExtended());
    EXPECT_EQ(message.frame.length(), 2);
    EXPECT_EQ(message.frame.byte(0), 0x01);
    EXPECT_EQ(message.frame.byte(1), 0x02);

    // Identifier 0x1ABCDEF is written with its leading zero.
    const SlcanMessage shorter = decode("T01ABCDEF20102\r");
    EXPECT_EQ(shorter.frame.id(), 0x01ABCDEFu);
    EXPECT_EQ(shorter.frame.length(), 2);
}

TEST(SlcanCodec, LinuxSlcanExamples)
{
    // The examples of Linux's drivers/net/can/slcan.
    EXPECT_EQ(decode("t1230\r").frame, CanFrame::makeData(0x123, IdFormat::Standard, nullptr, 0).value());
    const uint8_t three[3] = {0x11, 0x22, 0x33};
    EXPECT_EQ(decode("t4563112233\r").frame, CanFrame::makeData(0x456, IdFormat::Standard, three, 3).value());
    const uint8_t two[2] = {0xAA, 0x55};
    EXPECT_EQ(decode("T12ABCDEF2AA55\r").frame, CanFrame::makeData(0x12ABCDEF, IdFormat::Extended, two, 2).value());
    EXPECT_EQ(decode("r1230\r").frame, CanFrame::makeRemote(0x123, IdFormat::Standard, 0).value());
}

TEST(SlcanCodec, RemoteFramesCarryALengthOnly)
{
    const SlcanMessage standard = decode("r7FF8\r");
    EXPECT_TRUE(standard.frame.isRemote());
    EXPECT_EQ(standard.frame.id(), 0x7FFu);
    EXPECT_EQ(standard.frame.length(), 8);
    const SlcanMessage extended = decode("R1FFFFFFF3\r");
    EXPECT_TRUE(extended.frame.isRemote());
    EXPECT_TRUE(extended.frame.isExtended());
    EXPECT_EQ(extended.frame.id(), 0x1FFFFFFFu);
    EXPECT_EQ(extended.frame.length(), 3);
}

TEST(SlcanCodec, TimestampsAfterTheData)
{
    const SlcanMessage message = decode("t12321122EA5F\r");
    EXPECT_EQ(message.frame.length(), 2);
    EXPECT_TRUE(message.hasTimestamp);
    EXPECT_EQ(message.timestampMs, 59999);
    const SlcanMessage remote = decode("R000001230001A\r");
    EXPECT_TRUE(remote.frame.isRemote());
    EXPECT_TRUE(remote.hasTimestamp);
    EXPECT_EQ(remote.timestampMs, 0x001A);
    // The longest line: extended, 8 bytes, timestamp.
    const SlcanMessage longest = decode("T1111222281122334455667788EA5F\r");
    EXPECT_EQ(longest.frame.length(), 8);
    EXPECT_EQ(longest.frame.byte(7), 0x88);
    EXPECT_EQ(longest.timestampMs, 0xEA5F);
    // A timestamp beyond Lawicel's minute is kept rather than losing the frame.
    EXPECT_EQ(decode("t1230FFFF\r").timestampMs, 0xFFFF);
}

TEST(SlcanCodec, LowerCaseHexIsAccepted)
{
    const SlcanMessage message = decode("T1abcdef02a0bf\r");
    EXPECT_EQ(message.frame.id(), 0x1ABCDEF0u);
    EXPECT_EQ(message.frame.byte(0), 0xA0);
    EXPECT_EQ(message.frame.byte(1), 0xBF);
}

TEST(SlcanCodec, Commands)
{
    for (uint8_t index = 0; index <= 8; ++index) {
        const SlcanMessage message = decode(std::string("S") + char('0' + index) + "\r");
        EXPECT_EQ(message.kind, SlcanMessageKind::SetBitrate);
        EXPECT_EQ(message.bitrateIndex, index);
    }
    EXPECT_EQ(decode("O\r").kind, SlcanMessageKind::Open);
    EXPECT_EQ(decode("C\r").kind, SlcanMessageKind::Close);
    EXPECT_EQ(decode("F\r").kind, SlcanMessageKind::ReadStatusFlags);
    EXPECT_EQ(decode("V\r").kind, SlcanMessageKind::ReadVersion);
    EXPECT_EQ(decode("N\r").kind, SlcanMessageKind::ReadSerial);
    const SlcanMessage on = decode("Z1\r");
    EXPECT_EQ(on.kind, SlcanMessageKind::SetTimestamps);
    EXPECT_TRUE(on.timestampsOn);
    EXPECT_FALSE(decode("Z0\r").timestampsOn);
}

TEST(SlcanCodec, Replies)
{
    EXPECT_EQ(decode("\r").kind, SlcanMessageKind::Ok);
    EXPECT_EQ(decode("\a").kind, SlcanMessageKind::Error);
    const SlcanMessage standardAck = decode("z\r");
    EXPECT_EQ(standardAck.kind, SlcanMessageKind::TransmitAck);
    EXPECT_EQ(standardAck.ackFormat, IdFormat::Standard);
    EXPECT_EQ(decode("Z\r").ackFormat, IdFormat::Extended);
    const SlcanMessage flags = decode("F8c\r");
    EXPECT_EQ(flags.kind, SlcanMessageKind::StatusFlags);
    EXPECT_EQ(flags.statusFlags, SlcanCodec::kStatusBusError | SlcanCodec::kStatusDataOverrun
                                     | SlcanCodec::kStatusErrorWarning);
    const SlcanMessage version = decode("V1013\r");
    EXPECT_EQ(version.kind, SlcanMessageKind::Version);
    EXPECT_EQ(version.hardwareVersion, 0x10);
    EXPECT_EQ(version.softwareVersion, 0x13);
    const SlcanMessage serial = decode("NA123\r");
    EXPECT_EQ(serial.kind, SlcanMessageKind::Serial);
    EXPECT_EQ(std::string(serial.serial, 4), "A123");
}

TEST(SlcanCodec, LinuxOpenSequence)
{
    // What the slcan driver writes when the interface goes up at 500 kbit/s.
    SlcanCodec codec;
    const Fed fed = feed(codec, "C\rS6\rF\rO\r");
    ASSERT_EQ(fed.messages.size(), 4u);
    EXPECT_EQ(fed.messages[0].kind, SlcanMessageKind::Close);
    EXPECT_EQ(fed.messages[1].kind, SlcanMessageKind::SetBitrate);
    EXPECT_EQ(SlcanCodec::bitrate(fed.messages[1].bitrateIndex), 500000u);
    EXPECT_EQ(fed.messages[2].kind, SlcanMessageKind::ReadStatusFlags);
    EXPECT_EQ(fed.messages[3].kind, SlcanMessageKind::Open);
    EXPECT_EQ(codec.statistics().messages, 4u);
    EXPECT_EQ(codec.statistics().rejected, 0u);
}

TEST(SlcanCodec, LineFeedAfterCarriageReturnIsSkipped)
{
    SlcanCodec codec;
    const Fed fed = feed(codec, "O\r\nt1230\r\n");
    ASSERT_EQ(fed.messages.size(), 2u);
    EXPECT_TRUE(fed.rejections.empty());
    // Inside a line, a line feed is no hex digit.
    EXPECT_EQ(refusal("t12\n0\r"), LinkError::InvalidHexDigit);
}

TEST(SlcanCodec, BadHexDigits)
{
    EXPECT_EQ(refusal("t12G0\r"), LinkError::InvalidHexDigit);
    EXPECT_EQ(refusal("T1234567G0\r"), LinkError::InvalidHexDigit);
    EXPECT_EQ(refusal("t12321G22\r"), LinkError::InvalidHexDigit);
    EXPECT_EQ(refusal("t123211 2\r"), LinkError::InvalidHexDigit);
    EXPECT_EQ(refusal("t1230EA5X\r"), LinkError::InvalidHexDigit);
    EXPECT_EQ(refusal("FGG\r"), LinkError::InvalidHexDigit);
    EXPECT_EQ(refusal("V10x3\r"), LinkError::InvalidHexDigit);
    EXPECT_EQ(refusal(std::string("t12\0" "0\r", 6)), LinkError::InvalidHexDigit);
}

TEST(SlcanCodec, BadLengths)
{
    EXPECT_EQ(refusal("t\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("t123\r"), LinkError::InvalidLineLength);          // no DLC
    EXPECT_EQ(refusal("t1234112233\r"), LinkError::InvalidLineLength);   // 3 bytes of 4
    EXPECT_EQ(refusal("t12311122\r"), LinkError::InvalidLineLength);     // one byte too many
    EXPECT_EQ(refusal("t1230E\r"), LinkError::InvalidLineLength);        // timestamp of 1 digit
    EXPECT_EQ(refusal("t1230EA5\r"), LinkError::InvalidLineLength);      // timestamp of 3 digits
    EXPECT_EQ(refusal("t1230EA5F0\r"), LinkError::InvalidLineLength);    // timestamp of 5 digits
    EXPECT_EQ(refusal("T1234567\r"), LinkError::InvalidLineLength);      // 7 identifier digits, no DLC
    EXPECT_EQ(refusal("r123411223\r"), LinkError::InvalidLineLength);    // data after a remote frame
    EXPECT_EQ(refusal("S\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("S10\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("O1\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("C0\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("F1\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("F123\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("V12\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("N12345\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("Z10\r"), LinkError::InvalidLineLength);
    EXPECT_EQ(refusal("z1\r"), LinkError::InvalidLineLength);
}

TEST(SlcanCodec, BadDataLengthCodes)
{
    EXPECT_EQ(refusal("t1239\r"), LinkError::InvalidDataLength);
    EXPECT_EQ(refusal("t123A\r"), LinkError::InvalidDataLength);
    EXPECT_EQ(refusal("t123:\r"), LinkError::InvalidDataLength);
    EXPECT_EQ(refusal("R123456789\r"), LinkError::InvalidDataLength);
}

TEST(SlcanCodec, IdentifiersBeyondTheirFormat)
{
    EXPECT_EQ(refusal("t8000\r"), LinkError::InvalidIdentifier);
    EXPECT_EQ(refusal("tFFF0\r"), LinkError::InvalidIdentifier);
    EXPECT_EQ(refusal("T200000000\r"), LinkError::InvalidIdentifier);
    EXPECT_EQ(refusal("RFFFFFFFF0\r"), LinkError::InvalidIdentifier);
    EXPECT_EQ(decode("t7FF0\r").frame.id(), 0x7FFu);
}

TEST(SlcanCodec, UnknownCommands)
{
    for (const char* line : {"X\r", "P\r", "A\r", "L\r", "s0103\r", "M00000000\r", "e1a\r", "?\r", "\x01\r"}) {
        EXPECT_EQ(refusal(line), LinkError::UnknownCommand) << line;
    }
}

TEST(SlcanCodec, ArgumentsOutOfRange)
{
    EXPECT_EQ(refusal("S9\r"), LinkError::InvalidArgument);
    EXPECT_EQ(refusal("Sx\r"), LinkError::InvalidArgument);
    EXPECT_EQ(refusal("Z2\r"), LinkError::InvalidArgument);
    EXPECT_EQ(refusal("N12-4\r"), LinkError::InvalidArgument);
}

TEST(SlcanCodec, OverlongLineIsDroppedWholeAndParsingRecovers)
{
    SlcanCodec codec;
    // 31 characters: one more than the longest line.
    const std::string overlong = "T1111222281122334455667788EA5F0\r";
    const Fed fed = feed(codec, overlong + "t1230\r" + std::string(500, 'x') + "\rO\r");
    ASSERT_EQ(fed.rejections.size(), 2u);
    EXPECT_EQ(fed.rejections[0], LinkError::LineTooLong);
    EXPECT_EQ(fed.rejections[1], LinkError::LineTooLong);
    ASSERT_EQ(fed.messages.size(), 2u);
    EXPECT_EQ(fed.messages[0].frame.id(), 0x123u);
    EXPECT_EQ(fed.messages[1].kind, SlcanMessageKind::Open);
    EXPECT_EQ(codec.statistics().lineTooLong, 2u);
}

TEST(SlcanCodec, BellInTheMiddleOfALine)
{
    SlcanCodec codec;
    const Fed fed = feed(codec, "t12\at1230\r\a");
    ASSERT_EQ(fed.rejections.size(), 1u);
    EXPECT_EQ(fed.rejections[0], LinkError::LineInterrupted);
    ASSERT_EQ(fed.messages.size(), 2u);
    EXPECT_EQ(fed.messages[0].frame.id(), 0x123u);
    EXPECT_EQ(fed.messages[1].kind, SlcanMessageKind::Error);
    // A BELL also ends an overlong line.
    EXPECT_EQ(refusal(std::string(40, '1') + "\a"), LinkError::LineTooLong);
}

TEST(SlcanCodec, EveryRefusalIsCountedByReason)
{
    SlcanCodec codec;
    feed(codec, "t12G0\r" "t123\r" "t8000\r" "t1239\r" "X\r" "S9\r" "t1\a" + std::string(31, '0') + "\r"
                + "t1230\r" + "\r");
    const SlcanCodec::Statistics& statistics = codec.statistics();
    EXPECT_EQ(statistics.invalidHexDigit, 1u);
    EXPECT_EQ(statistics.invalidLineLength, 1u);
    EXPECT_EQ(statistics.invalidIdentifier, 1u);
    EXPECT_EQ(statistics.invalidDataLength, 1u);
    EXPECT_EQ(statistics.unknownCommand, 1u);
    EXPECT_EQ(statistics.invalidArgument, 1u);
    EXPECT_EQ(statistics.lineInterrupted, 1u);
    EXPECT_EQ(statistics.lineTooLong, 1u);
    EXPECT_EQ(statistics.rejected, 8u);
    EXPECT_EQ(statistics.messages, 2u);
}

TEST(SlcanCodec, GarbageBetweenGoodLinesLosesOnlyItsOwnLine)
{
    SlcanCodec codec;
    std::string stream;
    for (int i = 0; i < 50; ++i) {
        stream += "t1230\r";
        stream += std::string(i % 40, static_cast<char>('!' + i)) + "\r";
    }
    const Fed fed = feed(codec, stream);
    size_t frames = 0;
    for (const SlcanMessage& message : fed.messages) {
        frames += message.kind == SlcanMessageKind::Frame && message.frame.id() == 0x123 ? 1 : 0;
    }
    EXPECT_EQ(frames, 50u);
}

TEST(SlcanCodec, ResetDropsAPartialLine)
{
    SlcanCodec codec;
    feed(codec, "t12");
    codec.reset();
    const Fed fed = feed(codec, "O\r");
    ASSERT_EQ(fed.messages.size(), 1u);
    EXPECT_EQ(fed.messages[0].kind, SlcanMessageKind::Open);
}

TEST(SlcanCodec, FormatsFramesAsLinuxDoes)
{
    const uint8_t data[4] = {0x11, 0x22, 0x33, 0x44};
    EXPECT_EQ(format(frameMessage(CanFrame::makeData(0x123, IdFormat::Standard, data, 4).value())),
              "t123411223344\r");
    const uint8_t two[2] = {0x01, 0x02};
    EXPECT_EQ(format(frameMessage(CanFrame::makeData(0x1ABCDEF0, IdFormat::Extended, two, 2).value())),
              "T1ABCDEF020102\r");
    EXPECT_EQ(format(frameMessage(CanFrame::makeData(0x1ABCDEF, IdFormat::Extended, two, 2).value())),
              "T01ABCDEF20102\r");
    const uint8_t lower[2] = {0xab, 0xcd};
    EXPECT_EQ(format(frameMessage(CanFrame::makeData(0x00A, IdFormat::Standard, lower, 2).value())), "t00A2ABCD\r");
    EXPECT_EQ(format(frameMessage(CanFrame::makeRemote(0x7FF, IdFormat::Standard, 8).value())), "r7FF8\r");
    EXPECT_EQ(format(frameMessage(CanFrame::makeRemote(0x1F, IdFormat::Extended, 0).value())), "R0000001F0\r");

    SlcanMessage stamped = frameMessage(CanFrame::makeData(0x123, IdFormat::Standard, nullptr, 0).value());
    stamped.hasTimestamp = true;
    stamped.timestampMs = 0xEA5F;
    EXPECT_EQ(format(stamped), "t1230EA5F\r");
}

TEST(SlcanCodec, FormatsCommandsAndReplies)
{
    SlcanMessage message;
    message.kind = SlcanMessageKind::SetBitrate;
    message.bitrateIndex = 8;
    EXPECT_EQ(format(message), "S8\r");
    message.kind = SlcanMessageKind::Open;
    EXPECT_EQ(format(message), "O\r");
    message.kind = SlcanMessageKind::Close;
    EXPECT_EQ(format(message), "C\r");
    message.kind = SlcanMessageKind::ReadStatusFlags;
    EXPECT_EQ(format(message), "F\r");
    message.kind = SlcanMessageKind::StatusFlags;
    message.statusFlags = SlcanCodec::kStatusErrorPassive | SlcanCodec::kStatusReceiveQueueFull;
    EXPECT_EQ(format(message), "F21\r");
    message.kind = SlcanMessageKind::ReadVersion;
    EXPECT_EQ(format(message), "V\r");
    message.kind = SlcanMessageKind::Version;
    message.hardwareVersion = 0x10;
    message.softwareVersion = 0x13;
    EXPECT_EQ(format(message), "V1013\r");
    message.kind = SlcanMessageKind::ReadSerial;
    EXPECT_EQ(format(message), "N\r");
    message.kind = SlcanMessageKind::Serial;
    message.serial[0] = 'D';
    message.serial[1] = 'C';
    message.serial[2] = '0';
    message.serial[3] = 's';
    EXPECT_EQ(format(message), "NDC0s\r");
    message.kind = SlcanMessageKind::SetTimestamps;
    message.timestampsOn = true;
    EXPECT_EQ(format(message), "Z1\r");
    message.timestampsOn = false;
    EXPECT_EQ(format(message), "Z0\r");
    message.kind = SlcanMessageKind::Ok;
    EXPECT_EQ(format(message), "\r");
    message.kind = SlcanMessageKind::Error;
    EXPECT_EQ(format(message), "\a");
    message.kind = SlcanMessageKind::TransmitAck;
    message.ackFormat = IdFormat::Standard;
    EXPECT_EQ(format(message), "z\r");
    message.ackFormat = IdFormat::Extended;
    EXPECT_EQ(format(message), "Z\r");
}

TEST(SlcanCodec, FormatRefusals)
{
    SlcanMessage message;
    message.kind = SlcanMessageKind::SetBitrate;
    message.bitrateIndex = 9;
    char line[64];
    EXPECT_EQ(SlcanCodec::format(message, line, sizeof(line)).error(), LinkError::InvalidArgument);

    message = frameMessage(CanFrame());
    message.hasTimestamp = true;
    message.timestampMs = 60000;
    EXPECT_EQ(SlcanCodec::format(message, line, sizeof(line)).error(), LinkError::InvalidArgument);

    message.kind = SlcanMessageKind::Serial;
    message.serial[0] = 'A';
    message.serial[1] = ' ';
    message.serial[2] = 'B';
    message.serial[3] = 'C';
    EXPECT_EQ(SlcanCodec::format(message, line, sizeof(line)).error(), LinkError::InvalidArgument);

    message.kind = static_cast<SlcanMessageKind>(200);
    EXPECT_EQ(SlcanCodec::format(message, line, sizeof(line)).error(), LinkError::InvalidArgument);

    EXPECT_EQ(SlcanCodec::format(frameMessage(CanFrame()), nullptr, 10).error(), LinkError::InvalidArgument);
}

TEST(SlcanCodec, FormatNeedsRoomForTheWholeLine)
{
    const uint8_t data[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    SlcanMessage message = frameMessage(CanFrame::makeData(0x1FFFFFFF, IdFormat::Extended, data, 8).value());
    message.hasTimestamp = true;
    char line[SlcanCodec::kMaxLineLength + 1];
    const auto exact = SlcanCodec::format(message, line, sizeof(line));
    ASSERT_TRUE(exact.ok());
    EXPECT_EQ(exact.value(), SlcanCodec::kMaxLineLength + 1);
    EXPECT_EQ(SlcanCodec::format(message, line, sizeof(line) - 1).error(), LinkError::BufferTooSmall);
    EXPECT_EQ(SlcanCodec::format(message, nullptr, 0).error(), LinkError::BufferTooSmall);
}

TEST(SlcanCodec, EverythingFormattedParsesBack)
{
    std::vector<SlcanMessage> messages;
    for (uint8_t length = 0; length <= 8; ++length) {
        const uint8_t data[8] = {0x00, 0xFF, 0x5A, 0xA5, 0x01, 0x10, 0x7E, 0xE7};
        messages.push_back(frameMessage(CanFrame::makeData(0x700 + length, IdFormat::Standard, data, length).value()));
        messages.push_back(
            frameMessage(CanFrame::makeData(0x1F000000u + length, IdFormat::Extended, data, length).value()));
        messages.push_back(frameMessage(CanFrame::makeRemote(length, IdFormat::Extended, length).value()));
        SlcanMessage stamped = frameMessage(CanFrame::makeRemote(0x42, IdFormat::Standard, length).value());
        stamped.hasTimestamp = true;
        stamped.timestampMs = static_cast<uint16_t>(length * 7000);
        messages.push_back(stamped);
    }
    for (const SlcanMessage& message : messages) {
        const std::string line = format(message);
        const SlcanMessage back = decode(line);
        EXPECT_EQ(back.kind, SlcanMessageKind::Frame) << line;
        EXPECT_EQ(back.frame, message.frame) << line;
        EXPECT_EQ(back.hasTimestamp, message.hasTimestamp) << line;
        EXPECT_EQ(back.timestampMs, message.timestampMs) << line;
    }
}

TEST(SlcanCodec, BitrateTable)
{
    const uint32_t expected[9] = {10000, 20000, 50000, 100000, 125000, 250000, 500000, 800000, 1000000};
    for (uint8_t index = 0; index < 9; ++index) {
        EXPECT_EQ(SlcanCodec::bitrate(index), expected[index]);
        EXPECT_EQ(SlcanCodec::bitrateIndex(expected[index]).value(), index);
    }
    EXPECT_EQ(SlcanCodec::bitrate(9), 0u);
    EXPECT_EQ(SlcanCodec::bitrateIndex(83333).error(), LinkError::InvalidArgument);
}

TEST(SlcanCodec, ParseLineDirectly)
{
    EXPECT_EQ(SlcanCodec::parseLine("", 0).value().kind, SlcanMessageKind::Ok);
    EXPECT_EQ(SlcanCodec::parseLine(nullptr, 3).error(), LinkError::InvalidArgument);
    EXPECT_EQ(SlcanCodec::parseLine("t1230", 5).value().frame.id(), 0x123u);
}

} // namespace
