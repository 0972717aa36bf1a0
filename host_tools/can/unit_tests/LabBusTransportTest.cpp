// The lab bus transport's reading and writing of the hub's lines
// (docs/protocols/labbus.md, "Messages"); the conversation itself is tested
// against the hub in tests_renode/test_dcos_can_labbus.py.
#include <hostcan/LabBusTransport.hpp>

#include <gtest/gtest.h>

namespace {

using hostcan::LabBusTransport;
using hostcan::Received;
using hostcan::TransportError;

TEST(LabBusLines, FramesAreWrittenAsTheHubReadsThem)
{
    const uint8_t bytes[] = {0x01, 0xAB};
    EXPECT_EQ(LabBusTransport::frameWords(can::CanFrame::makeData(0x123, can::IdFormat::Standard, bytes, 2).value()),
              "123 SD 2 01ab");
    EXPECT_EQ(LabBusTransport::frameWords(can::CanFrame::makeRemote(0x1ABCDEF0, can::IdFormat::Extended, 8).value()),
              "1abcdef0 XR 8 -");
    EXPECT_EQ(LabBusTransport::frameWords(can::CanFrame::makeData(0x7, can::IdFormat::Extended, nullptr, 0).value()),
              "7 XD 0 -");
}

TEST(LabBusLines, ReceivedFramesCarryTheirEmulatedTime)
{
    TransportError error;
    const std::optional<Received> r = LabBusTransport::parseEvent("RX 0 0 4344777 123 SD 2 0102 0", error);
    ASSERT_TRUE(r) << error.message;
    EXPECT_EQ(r->kind, Received::Kind::Frame);
    EXPECT_EQ(r->frame.id(), 0x123u);
    EXPECT_EQ(r->frame.byte(1), 0x02);
    EXPECT_EQ(r->timestamp.count(), 4344777);
    EXPECT_TRUE(r->emulatedTime);
    const std::optional<Received> remote = LabBusTransport::parseEvent("RX 0 3 99 1abcdef0 XR 4 - 0", error);
    ASSERT_TRUE(remote);
    EXPECT_TRUE(remote->frame.isRemote() && remote->frame.isExtended());
    EXPECT_EQ(remote->frame.length(), 4);
}

TEST(LabBusLines, ErrorsBecomeEventsAndTheRestIsQuiet)
{
    TransportError error;
    std::optional<Received> r = LabBusTransport::parseEvent("ERR 0 0 500 tx d9 ack", error);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->event, hostcan::BusEventKind::NoAcknowledge);
    r = LabBusTransport::parseEvent("ERR 0 0 500 rx 58 -", error);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->event, hostcan::BusEventKind::BusError);
    r = LabBusTransport::parseEvent("FAULT 0 0 500 busoff", error);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->event, hostcan::BusEventKind::BusOff);
    r = LabBusTransport::parseEvent("RX 0 0 500 123 SD 12 0102030405060708 0", error);
    ASSERT_TRUE(r) << "a DLC above 8 is reported, not passed on as a frame";
    EXPECT_EQ(r->kind, Received::Kind::Event);
    for (const char* quiet : {"SOF 0 0 100 tx", "IDLE 0 0 100", "TXOK 0 0 100", "DONE FAULT", "LOST 0 0 100 5 0", ""}) {
        EXPECT_FALSE(LabBusTransport::parseEvent(quiet, error)) << quiet;
        EXPECT_FALSE(error) << quiet;
    }
}

TEST(LabBusLines, NonsenseFromTheHubIsAProtocolError)
{
    for (const char* bad : {"RX 0 0 500 12G SD 1 00 0", "RX 0 0 500 123 QQ 1 00 0", "RX 0 0 500 123 SD 2 01 0",
                            "RX 0 0 500 123 SD 1 0Z 0", "RX 0 0 500 800 SD 0 - 0", "ERROR you are not welcome"}) {
        TransportError error;
        EXPECT_FALSE(LabBusTransport::parseEvent(bad, error)) << bad;
        EXPECT_EQ(error.kind, TransportError::Kind::Protocol) << bad;
    }
}

} // namespace
