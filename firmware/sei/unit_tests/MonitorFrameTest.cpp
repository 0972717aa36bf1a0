// The monitoring stream's frames (docs/protocols/monitor.md): each layout
// byte for byte, every sample format's extension, and the decoder's
// refusal of every frame that is not exactly one of the layouts.
#include <sei/MonitorFrame.hpp>

#include <gtest/gtest.h>

#include <vector>

namespace {

using sei::MonitorEndReason;
using sei::MonitorFrame;
using sei::MonitorFrameKind;
using sei::SeiSampleFormat;

std::vector<uint8_t> encoded(const MonitorFrame& frame)
{
    uint8_t bytes[sei::kMonitorFrameMax] = {};
    const size_t length = frame.encode(bytes);
    return std::vector<uint8_t>(bytes, bytes + length);
}

bool decodes(const std::vector<uint8_t>& bytes, MonitorFrame& out)
{
    return MonitorFrame::decode(bytes.data(), bytes.size(), out);
}

TEST(MonitorFrame, SampleLayoutByteForByte)
{
    MonitorFrame frame;
    frame.kind = MonitorFrameKind::Sample;
    frame.channel = 7;
    frame.timeMs = 0xBEEF;
    frame.value = -2;
    EXPECT_EQ(encoded(frame), (std::vector<uint8_t>{0x01, 0x07, 0xEF, 0xBE, 0xFE, 0xFF, 0xFF, 0xFF}));
    MonitorFrame back;
    ASSERT_TRUE(decodes(encoded(frame), back));
    EXPECT_EQ(back.kind, MonitorFrameKind::Sample);
    EXPECT_EQ(back.channel, 7);
    EXPECT_EQ(back.timeMs, 0xBEEF);
    EXPECT_EQ(back.value, -2);
}

TEST(MonitorFrame, LogLostAndEndLayouts)
{
    MonitorFrame log;
    log.kind = MonitorFrameKind::Log;
    log.sequence = 0xFF;
    log.textLength = 3;
    log.text[0] = 'o';
    log.text[1] = 'k';
    log.text[2] = '\n';
    EXPECT_EQ(encoded(log), (std::vector<uint8_t>{0x02, 0xFF, 'o', 'k', '\n'}));
    MonitorFrame back;
    ASSERT_TRUE(decodes(encoded(log), back));
    EXPECT_EQ(back.kind, MonitorFrameKind::Log);
    EXPECT_EQ(back.sequence, 0xFF);
    ASSERT_EQ(back.textLength, 3);
    EXPECT_EQ(back.text[1], 'k');

    MonitorFrame lost;
    lost.kind = MonitorFrameKind::Lost;
    lost.lostBytes = 0x1234;
    EXPECT_EQ(encoded(lost), (std::vector<uint8_t>{0x03, 0x34, 0x12}));
    ASSERT_TRUE(decodes(encoded(lost), back));
    EXPECT_EQ(back.kind, MonitorFrameKind::Lost);
    EXPECT_EQ(back.lostBytes, 0x1234);

    for (const MonitorEndReason reason :
         {MonitorEndReason::LeaseExpired, MonitorEndReason::Stopped, MonitorEndReason::Replaced}) {
        MonitorFrame end;
        end.kind = MonitorFrameKind::End;
        end.reason = reason;
        EXPECT_EQ(encoded(end), (std::vector<uint8_t>{0x04, static_cast<uint8_t>(reason)}));
        ASSERT_TRUE(decodes(encoded(end), back));
        EXPECT_EQ(back.kind, MonitorFrameKind::End);
        EXPECT_EQ(back.reason, reason);
    }
}

TEST(MonitorFrame, EveryLogLengthFromOneToSixRoundTrips)
{
    for (uint8_t length = 1; length <= sei::kMonitorLogText; ++length) {
        MonitorFrame log;
        log.kind = MonitorFrameKind::Log;
        log.sequence = length;
        log.textLength = length;
        for (uint8_t i = 0; i < length; ++i) {
            log.text[i] = static_cast<uint8_t>('a' + i);
        }
        const std::vector<uint8_t> bytes = encoded(log);
        ASSERT_EQ(bytes.size(), 2u + length);
        MonitorFrame back;
        ASSERT_TRUE(decodes(bytes, back));
        EXPECT_EQ(back.textLength, length);
        EXPECT_EQ(back.text[length - 1], 'a' + length - 1);
    }
}

TEST(MonitorFrame, EncodeRefusesFieldsOutOfRange)
{
    MonitorFrame frame;
    frame.kind = MonitorFrameKind::Sample;
    frame.channel = 8;
    EXPECT_TRUE(encoded(frame).empty());
    frame.kind = MonitorFrameKind::Log;
    frame.textLength = 0;
    EXPECT_TRUE(encoded(frame).empty());
    frame.textLength = 7;
    EXPECT_TRUE(encoded(frame).empty());
    frame.kind = MonitorFrameKind::Lost;
    frame.lostBytes = 0;
    EXPECT_TRUE(encoded(frame).empty());
    frame.kind = MonitorFrameKind::End;
    frame.reason = static_cast<MonitorEndReason>(0);
    EXPECT_TRUE(encoded(frame).empty());
    frame.reason = static_cast<MonitorEndReason>(4);
    EXPECT_TRUE(encoded(frame).empty());
}

TEST(MonitorFrame, DecodeRefusesMalformedFrames)
{
    const std::vector<std::vector<uint8_t>> refused = {
        {},                                               // nothing
        {0x00, 1, 2, 3, 4, 5, 6, 7},                      // kind 0
        {0x05, 0x01},                                     // kind 5
        {0xFF},                                           // kind 255
        {0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00},       // sample one byte short
        {0x01, 0x08, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00}, // channel 8
        {0x01},                                           // sample kind alone
        {0x02, 0x00},                                     // log without text
        {0x02},                                           // log kind alone
        {0x03, 0x00, 0x00},                               // nothing lost
        {0x03, 0x01},                                     // lost short
        {0x03, 0x01, 0x00, 0x00},                         // lost long
        {0x04},                                           // end without reason
        {0x04, 0x00},                                     // reason 0
        {0x04, 0x04},                                     // reason 4
        {0x04, 0x01, 0x00},                               // end long
    };
    for (const std::vector<uint8_t>& bytes : refused) {
        MonitorFrame out;
        out.channel = 0x55;
        EXPECT_FALSE(decodes(bytes, out)) << bytes.size();
        EXPECT_EQ(out.channel, 0x55) << "a refused frame leaves the output alone";
    }
    const uint8_t nine[9] = {0x02, 0, 'a', 'b', 'c', 'd', 'e', 'f', 'g'};
    MonitorFrame out;
    EXPECT_FALSE(MonitorFrame::decode(nine, sizeof nine, out));
    EXPECT_FALSE(MonitorFrame::decode(nullptr, 3, out));
}

TEST(MonitorFrame, EveryFormatIsSignOrZeroExtended)
{
    uint8_t page[sei::kSeiPageSize] = {};
    // 0xFF..: the all-ones pattern reads as the largest unsigned value or -1.
    for (uint8_t& byte : page) {
        byte = 0xFF;
    }
    EXPECT_EQ(sei::monitorSampleValue(page, 0, SeiSampleFormat::U8), 255);
    EXPECT_EQ(sei::monitorSampleValue(page, 0, SeiSampleFormat::I8), -1);
    EXPECT_EQ(sei::monitorSampleValue(page, 0, SeiSampleFormat::U16), 65535);
    EXPECT_EQ(sei::monitorSampleValue(page, 0, SeiSampleFormat::I16), -1);
    EXPECT_EQ(sei::monitorSampleValue(page, 0, SeiSampleFormat::U32), -1);
    EXPECT_EQ(sei::monitorSampleMeaning(sei::monitorSampleValue(page, 0, SeiSampleFormat::U32), SeiSampleFormat::U32),
              4294967295LL);
    EXPECT_EQ(sei::monitorSampleValue(page, 0, SeiSampleFormat::I32), -1);
    EXPECT_EQ(sei::monitorSampleMeaning(-1, SeiSampleFormat::I32), -1);

    // A positive value just below each sign bit, little-endian at an offset.
    uint8_t values[sei::kSeiPageSize] = {0x7F, 0xFF, 0x7F, 0xFF, 0xFF, 0xFF, 0x7F, 0x80, 0x00, 0x80, 0x00, 0x00,
                                         0x00, 0x80, 0x00, 0x00};
    EXPECT_EQ(sei::monitorSampleValue(values, 0, SeiSampleFormat::I8), 127);
    EXPECT_EQ(sei::monitorSampleValue(values, 1, SeiSampleFormat::I16), 0x7FFF);
    EXPECT_EQ(sei::monitorSampleValue(values, 3, SeiSampleFormat::I32), 0x7FFFFFFF);
    EXPECT_EQ(sei::monitorSampleValue(values, 7, SeiSampleFormat::I8), -128);
    EXPECT_EQ(sei::monitorSampleValue(values, 7, SeiSampleFormat::U8), 128);
    EXPECT_EQ(sei::monitorSampleValue(values, 8, SeiSampleFormat::I16), -32768);
    EXPECT_EQ(sei::monitorSampleValue(values, 8, SeiSampleFormat::U16), 32768);
    EXPECT_EQ(sei::monitorSampleValue(values, 10, SeiSampleFormat::I32), INT32_MIN);
    EXPECT_EQ(sei::monitorSampleMeaning(sei::monitorSampleValue(values, 10, SeiSampleFormat::U32),
                                        SeiSampleFormat::U32),
              2147483648LL);
    // The last field that fits, and the first that does not.
    EXPECT_EQ(sei::monitorSampleValue(values, 12, SeiSampleFormat::U32), static_cast<int32_t>(0x00008000));
    EXPECT_EQ(sei::monitorSampleValue(values, 13, SeiSampleFormat::U32), 0);
    EXPECT_EQ(sei::monitorSampleValue(values, 15, SeiSampleFormat::U8), 0);
    EXPECT_EQ(sei::monitorSampleValue(values, 15, SeiSampleFormat::I16), 0);
}

} // namespace
