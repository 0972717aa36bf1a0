// dcos-mon's reading of the stream (docs/protocols/monitor.md): the 16-bit
// millisecond time unwrapped across wraps and lost samples, console text
// put back into lines, gaps in the Log sequence and the node's Lost frames
// reported, the end, malformed frames counted and left out, and the
// --data fields' syntax.
#include <hostmon/ChannelSpec.hpp>
#include <hostmon/StreamDecoder.hpp>

#include <can/MessageIdentifier.hpp>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using hostmon::StreamEvent;

constexpr int64_t kMs = 1'000'000;

std::vector<uint8_t> sample(uint8_t channel, uint16_t timeMs, int32_t value)
{
    sei::MonitorFrame frame;
    frame.kind = sei::MonitorFrameKind::Sample;
    frame.channel = channel;
    frame.timeMs = timeMs;
    frame.value = value;
    uint8_t bytes[sei::kMonitorFrameMax];
    const size_t length = frame.encode(bytes);
    return std::vector<uint8_t>(bytes, bytes + length);
}

std::vector<uint8_t> log(uint8_t sequence, const std::string& text)
{
    std::vector<uint8_t> bytes{0x02, sequence};
    bytes.insert(bytes.end(), text.begin(), text.end());
    return bytes;
}

std::vector<StreamEvent> feed(hostmon::StreamDecoder& decoder, const std::vector<uint8_t>& bytes, int64_t atNs)
{
    std::vector<StreamEvent> out;
    decoder.onFrame(bytes.data(), bytes.size(), atNs, out);
    return out;
}

TEST(TimeUnwrapper, FollowsWrapsEvenAcrossLostSamples)
{
    hostmon::TimeUnwrapper unwrapper;
    EXPECT_EQ(unwrapper.unwrap(65000, 0), 65000);
    EXPECT_EQ(unwrapper.unwrap(65500, 500 * kMs), 65500);
    EXPECT_EQ(unwrapper.unwrap(464, 1000 * kMs), 66000) << "one wrap";
    // Forty seconds of samples lost: the host's clock says how many wraps.
    EXPECT_EQ(unwrapper.unwrap(static_cast<uint16_t>((66000 + 40000) % 65536), 41000 * kMs), 106000);
    // A host that saw the frame late by a few seconds still picks the right wrap.
    EXPECT_EQ(unwrapper.unwrap(static_cast<uint16_t>((106000 + 100) % 65536), 46000 * kMs), 106100);
    // Two channels of one period carry the same time.
    EXPECT_EQ(unwrapper.unwrap(static_cast<uint16_t>((106000 + 100) % 65536), 46000 * kMs), 106100);
}

TEST(StreamDecoder, SamplesAreInSecondsSinceTheFirst)
{
    hostmon::StreamDecoder decoder;
    std::vector<StreamEvent> events = feed(decoder, sample(0, 65530, 7), 0);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, StreamEvent::Kind::Sample);
    EXPECT_DOUBLE_EQ(events[0].seconds, 0.0);
    EXPECT_EQ(events[0].value, 7);
    events = feed(decoder, sample(1, 94, -3), 100 * kMs);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].channel, 1);
    EXPECT_DOUBLE_EQ(events[0].seconds, 0.1);
    EXPECT_EQ(events[0].value, -3);
}

TEST(StreamDecoder, ConsoleTextBecomesLines)
{
    hostmon::StreamDecoder decoder;
    std::vector<StreamEvent> events;
    for (const auto& [sequence, text] : std::vector<std::pair<uint8_t, std::string>>{
             {0, "hello,"}, {1, " world"}, {2, "\r\nramp"}, {3, ": 1\r\n"}}) {
        const std::vector<StreamEvent> more = feed(decoder, log(sequence, text), 0);
        events.insert(events.end(), more.begin(), more.end());
    }
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].kind, StreamEvent::Kind::LogLine);
    EXPECT_EQ(events[0].text, "hello, world");
    EXPECT_EQ(events[1].text, "ramp: 1");
    events = feed(decoder, log(4, "dcos> "), 0);
    EXPECT_TRUE(events.empty());
    EXPECT_TRUE(decoder.hasPartialLine());
    decoder.flush(events);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].text, "dcos> ");
}

TEST(StreamDecoder, AGapInTheSequenceIsReportedAndWrapsModulo256)
{
    hostmon::StreamDecoder decoder;
    feed(decoder, log(254, "a"), 0);
    EXPECT_TRUE(feed(decoder, log(255, "b"), 0).empty());
    EXPECT_TRUE(feed(decoder, log(0, "c"), 0).empty()) << "255 to 0 is no gap";
    const std::vector<StreamEvent> events = feed(decoder, log(3, "d\n"), 0);
    ASSERT_EQ(events.size(), 3u);
    EXPECT_EQ(events[0].kind, StreamEvent::Kind::LogLine);
    EXPECT_EQ(events[0].text, "abc") << "the line cut short is shown as it was";
    EXPECT_EQ(events[1].kind, StreamEvent::Kind::LogGap);
    EXPECT_EQ(events[1].count, 2u);
    EXPECT_EQ(events[2].text, "d");
    EXPECT_EQ(decoder.logFramesLost(), 2u);
}

TEST(StreamDecoder, LostBytesAndTheEnd)
{
    hostmon::StreamDecoder decoder;
    std::vector<StreamEvent> events = feed(decoder, {0x03, 0x10, 0x00}, 0);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, StreamEvent::Kind::LogLost);
    EXPECT_EQ(events[0].count, 16u);
    feed(decoder, log(0, "part"), 0);
    events = feed(decoder, {0x04, 0x03}, 0);
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].text, "part");
    EXPECT_EQ(events[1].kind, StreamEvent::Kind::End);
    EXPECT_EQ(events[1].reason, sei::MonitorEndReason::Replaced);
}

TEST(StreamDecoder, MalformedFramesAreCountedAndSayNothing)
{
    hostmon::StreamDecoder decoder;
    EXPECT_TRUE(feed(decoder, {0x01, 0x00, 0x00}, 0).empty());
    EXPECT_TRUE(feed(decoder, {0x09}, 0).empty());
    EXPECT_TRUE(feed(decoder, {0x04, 0x09}, 0).empty());
    EXPECT_EQ(decoder.malformed(), 3u);
}

TEST(StreamDecoder, PrintableLineDropsTerminalControl)
{
    EXPECT_EQ(hostmon::printableLine("dcos> hex\b\belp\r"), "dcos> help");
    EXPECT_EQ(hostmon::printableLine("\x1b[2Kline\x1b[1;31m red\x07"), "line red");
    EXPECT_EQ(hostmon::printableLine("tab\there"), "tab\there");
}

TEST(StreamDecoder, OnlyTheNodesFramesToThisHostBelongToTheStream)
{
    const auto frame = [](can::MessageType type, uint8_t destination, uint8_t source) {
        const uint8_t data[] = {0x04, 0x01};
        return can::CanFrame::makeData(
                   can::MessageIdentifier::make(31, type, destination, source).value().encode(),
                   can::IdFormat::Extended, data, sizeof data)
            .value();
    };
    EXPECT_TRUE(hostmon::isStreamFrame(frame(can::MessageType::Monitoring, 254, 3), 254, 3));
    EXPECT_FALSE(hostmon::isStreamFrame(frame(can::MessageType::Monitoring, 253, 3), 254, 3));
    EXPECT_FALSE(hostmon::isStreamFrame(frame(can::MessageType::Monitoring, 254, 4), 254, 3));
    EXPECT_FALSE(hostmon::isStreamFrame(frame(can::MessageType::Configuration, 254, 3), 254, 3));
}

TEST(ChannelSpec, EveryPartAndItsDefaults)
{
    std::string why;
    auto spec = hostmon::parseChannelSpec("ramp", why);
    ASSERT_TRUE(spec) << why;
    EXPECT_EQ(spec->publisherName, "ramp");
    EXPECT_EQ(spec->offset, 0);
    EXPECT_EQ(spec->format, sei::SeiSampleFormat::I32);
    EXPECT_EQ(spec->label, "ramp");
    spec = hostmon::parseChannelSpec("0x00038005@4:i16=level", why);
    ASSERT_TRUE(spec) << why;
    EXPECT_TRUE(spec->publisherName.empty());
    EXPECT_EQ(spec->publisherId, 0x00038005u);
    EXPECT_EQ(spec->offset, 4);
    EXPECT_EQ(spec->format, sei::SeiSampleFormat::I16);
    EXPECT_EQ(spec->label, "level");
    spec = hostmon::parseChannelSpec("ramp@15:u8", why);
    ASSERT_TRUE(spec) << why;
    EXPECT_EQ(spec->label, "ramp@15:u8");
    spec = hostmon::parseChannelSpec("ramp=a=b", why);
    ASSERT_TRUE(spec) << why;
    EXPECT_EQ(spec->label, "a=b");
}

TEST(ChannelSpec, RefusesWhatIsNotAField)
{
    for (const char* text : {"", "@2", "ramp@16", "ramp@13:i32", "ramp@:u8", "ramp@x", "ramp:f32", "ramp=",
                             "ramp=two words", "0x", "0x0", "0x123456789", "0xZZ", "averyveryverylongname",
                             "has space"}) {
        std::string why;
        EXPECT_FALSE(hostmon::parseChannelSpec(text, why)) << text;
        EXPECT_FALSE(why.empty()) << text;
    }
}

} // namespace
