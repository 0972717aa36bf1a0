// The slcan transport against a scripted adapter on the other end of a
// socketpair: the bring-up handshake, frames both ways, refusals, silence
// and a vanished adapter.
#include <hostcan/SlcanTransport.hpp>
#include <hostcan/SocketCanTransport.hpp>

#include <gtest/gtest.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>
#include <thread>

namespace {

using hostcan::Received;
using hostcan::SlcanTransport;
using hostcan::TransportError;
using namespace std::chrono_literals;

// Reads what the transport wrote, up to the next CR.
std::string readLine(int fd)
{
    std::string line;
    char c;
    while (::read(fd, &c, 1) == 1) {
        line += c;
        if (c == '\r') {
            break;
        }
    }
    return line;
}

void writeText(int fd, const std::string& text) { ASSERT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size())); }

struct Pair {
    Pair() { EXPECT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0); }
    ~Pair() { ::close(fds[1]); }
    int fds[2];
};

TEST(SlcanTransportTest, BringsTheAdapterUpAndExchangesFrames)
{
    Pair pair;
    std::thread adapter([&] {
        EXPECT_EQ(readLine(pair.fds[1]), "C\r");
        writeText(pair.fds[1], "\r");
        EXPECT_EQ(readLine(pair.fds[1]), "S5\r") << "250 kbit/s is S5";
        writeText(pair.fds[1], "\r");
        EXPECT_EQ(readLine(pair.fds[1]), "O\r");
        // A frame from the bus before the reply is kept, not lost.
        writeText(pair.fds[1], "t1232AABB\r\r");
    });
    TransportError error;
    std::unique_ptr<SlcanTransport> transport = SlcanTransport::adopt(pair.fds[0], "test", 250'000, error);
    adapter.join();
    ASSERT_TRUE(transport) << error.message;
    Received r = transport->receive(1000ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame) << error.message;
    EXPECT_EQ(r.frame.id(), 0x123u);
    EXPECT_EQ(r.frame.length(), 2);
    EXPECT_EQ(r.frame.byte(1), 0xBB);
    // Frames from the adapter, with noise between them that is refused and counted.
    writeText(pair.fds[1], "T1ABCDEF020102\rxyz\rz\rt7FF0\r");
    r = transport->receive(1000ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame);
    EXPECT_TRUE(r.frame.isExtended());
    EXPECT_EQ(r.frame.id(), 0x1ABCDEF0u);
    r = transport->receive(1000ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame) << "the bad line did not stop the next one";
    EXPECT_EQ(r.frame.id(), 0x7FFu);
    EXPECT_EQ(transport->statistics().rejected, 1u);
    // Our frames go out as Lawicel lines.
    const uint8_t bytes[] = {0xDE, 0xAD};
    EXPECT_FALSE(transport->send(can::CanFrame::makeData(0x1F, can::IdFormat::Extended, bytes, 2).value(), 100ms));
    EXPECT_EQ(readLine(pair.fds[1]), "T0000001F2DEAD\r");
    // Nothing more: a time-out, not an error.
    r = transport->receive(50ms, error);
    EXPECT_EQ(r.kind, Received::Kind::Timeout);
    EXPECT_FALSE(error);
    // Status flags become events.
    writeText(pair.fds[1], "F20\r");
    r = transport->receive(1000ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Event);
    EXPECT_EQ(r.event, hostcan::BusEventKind::ErrorPassive);
    EXPECT_EQ(transport->bitRate(), 250'000u);
}

TEST(SlcanTransportTest, AnAdapterThatRefusesTheBitRateIsReported)
{
    Pair pair;
    std::thread adapter([&] {
        (void)readLine(pair.fds[1]);
        writeText(pair.fds[1], "\a");
        (void)readLine(pair.fds[1]);
        writeText(pair.fds[1], "\a");
    });
    TransportError error;
    EXPECT_FALSE(SlcanTransport::adopt(pair.fds[0], "test", 500'000, error));
    adapter.join();
    EXPECT_EQ(error.kind, TransportError::Kind::Refused) << error.message;
}

TEST(SlcanTransportTest, ASilentAdapterTimesOut)
{
    Pair pair;
    TransportError error;
    EXPECT_FALSE(SlcanTransport::adopt(pair.fds[0], "test", 500'000, error));
    EXPECT_EQ(error.kind, TransportError::Kind::Protocol);
    EXPECT_NE(error.message.find("did not answer"), std::string::npos) << error.message;
}

TEST(SlcanTransportTest, ABitRateTheProtocolLacksIsABadArgument)
{
    Pair pair;
    TransportError error;
    EXPECT_FALSE(SlcanTransport::adopt(pair.fds[0], "test", 333'000, error));
    EXPECT_EQ(error.kind, TransportError::Kind::BadArgument);
}

TEST(SlcanTransportTest, AnAdapterThatGoesAwayIsReported)
{
    int fds[2];
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
    std::thread adapter([&] {
        for (int i = 0; i < 3; ++i) {
            (void)readLine(fds[1]);
            writeText(fds[1], "\r");
        }
    });
    TransportError error;
    std::unique_ptr<SlcanTransport> transport = SlcanTransport::adopt(fds[0], "test", 500'000, error);
    adapter.join();
    ASSERT_TRUE(transport);
    ::close(fds[1]);
    const Received r = transport->receive(1000ms, error);
    EXPECT_EQ(r.kind, Received::Kind::Timeout);
    EXPECT_EQ(error.kind, TransportError::Kind::Closed);
}

TEST(TransportNames, SpecsAreCheckedBeforeAnythingIsOpened)
{
    TransportError error;
    EXPECT_FALSE(hostcan::openTransport("slcan:", error));
    EXPECT_EQ(error.kind, TransportError::Kind::BadArgument);
    EXPECT_FALSE(hostcan::openTransport("slcan:/dev/ttyACM0@fast", error));
    EXPECT_EQ(error.kind, TransportError::Kind::BadArgument);
    EXPECT_FALSE(hostcan::openTransport("gizmo:1", error));
    EXPECT_EQ(error.kind, TransportError::Kind::BadArgument);
    EXPECT_FALSE(hostcan::openTransport("slcan:/dev/does-not-exist", error));
    EXPECT_EQ(error.kind, TransportError::Kind::NotAvailable);
    EXPECT_FALSE(hostcan::openTransport("a-name-far-too-long-for-a-netdev", error));
    EXPECT_EQ(error.kind, TransportError::Kind::BadArgument);
}

TEST(LinuxErrorFrames, EveryClassBecomesAnEvent)
{
    hostcan::LinuxErrorFrame frame;
    frame.canId = CAN_ERR_FLAG | CAN_ERR_CRTL | CAN_ERR_ACK | CAN_ERR_CNT;
    frame.data[1] = CAN_ERR_CRTL_TX_PASSIVE;
    frame.data[6] = 136;
    std::vector<Received> events = hostcan::decodeErrorFrame(frame);
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].event, hostcan::BusEventKind::ErrorPassive);
    EXPECT_NE(events[0].detail.find("tx errors 136"), std::string::npos) << events[0].detail;
    EXPECT_EQ(events[1].event, hostcan::BusEventKind::NoAcknowledge);
    frame = {};
    frame.canId = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
    events = hostcan::decodeErrorFrame(frame);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].event, hostcan::BusEventKind::BusOff);
    frame.canId = CAN_ERR_FLAG | CAN_ERR_RESTARTED;
    EXPECT_EQ(hostcan::decodeErrorFrame(frame)[0].event, hostcan::BusEventKind::Restarted);
}

} // namespace
