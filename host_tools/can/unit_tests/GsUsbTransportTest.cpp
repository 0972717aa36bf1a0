// The gs_usb transport against a scripted fake adapter: the requests it
// sends on open and close with their exact bytes, frames out and their
// echoes, frames and error frames in, the overflow flag, transfers that make
// no sense, an adapter unplugged in the middle, and the `-i gsusb...` forms.
#include <hostcan/GsUsbTransport.hpp>

#include <gtest/gtest.h>

#include <linux/can.h>
#include <linux/can/error.h>

#include <deque>
#include <map>
#include <memory>
#include <thread>
#include <vector>

namespace {

using namespace hostcan;
using namespace std::chrono_literals;
using Bytes = std::vector<uint8_t>;
using Status = UsbResult::Status;

struct ControlCall {
    bool in = false;
    uint8_t request = 0;
    uint16_t value = 0;
    uint16_t index = 0;
    Bytes data;     // What an OUT request carried.
    size_t length = 0; // What an IN request asked for.
};

// One queued IN transfer: bytes, or a failure of the transfer.
struct InItem {
    Bytes bytes;
    Status status = Status::Ok;
};

// What the fake did and will do; the test keeps it after the transport
// (which owns the fake) is gone, to see what closing sent.
struct FakeState {
    std::vector<ControlCall> calls;
    std::map<uint8_t, Bytes> replies;    // IN requests' answers, by bRequest.
    std::map<uint8_t, Status> failures;  // Requests that fail, by bRequest.
    std::deque<InItem> in;
    std::vector<Bytes> out;              // Bulk OUT transfers, in order.
    bool echo = true;                    // Return every frame sent, as an adapter does once it is on the bus.
    bool unplugged = false;
    uint8_t interfaceNumber = 0;
};

class FakeGsUsbDevice final : public GsUsbDevice {
public:
    explicit FakeGsUsbDevice(std::shared_ptr<FakeState> state) : state_(std::move(state)) {}

    std::string description() const override { return "fake adapter"; }
    uint8_t interfaceNumber() const override { return state_->interfaceNumber; }
    size_t inPacketSize() const override { return 64; }

    UsbResult controlIn(uint8_t request, uint16_t value, uint16_t index, uint8_t* data, size_t length,
                        std::chrono::milliseconds) override
    {
        state_->calls.push_back({true, request, value, index, {}, length});
        if (UsbResult r = failure(request); !r.ok()) {
            return r;
        }
        const Bytes& reply = state_->replies[request];
        const size_t n = std::min(length, reply.size());
        std::copy(reply.begin(), reply.begin() + static_cast<long>(n), data);
        UsbResult r;
        r.length = n;
        return r;
    }

    UsbResult controlOut(uint8_t request, uint16_t value, uint16_t index, const uint8_t* data, size_t length,
                         std::chrono::milliseconds) override
    {
        state_->calls.push_back({false, request, value, index, Bytes(data, data + length), 0});
        if (UsbResult r = failure(request); !r.ok()) {
            return r;
        }
        UsbResult r;
        r.length = length;
        return r;
    }

    UsbResult bulkIn(uint8_t* data, size_t capacity, std::chrono::milliseconds timeout) override
    {
        if (state_->unplugged) {
            return {Status::NoDevice, 0, "no device"};
        }
        if (state_->in.empty()) {
            // Nothing to read: wait a little of the time-out, as a quiet bus would.
            std::this_thread::sleep_for(std::min(timeout, std::chrono::milliseconds(2)));
            return {Status::Timeout, 0, "timeout"};
        }
        InItem item = state_->in.front();
        state_->in.pop_front();
        if (item.status == Status::NoDevice) {
            state_->unplugged = true;
        }
        if (item.status != Status::Ok) {
            return {item.status, 0, "scripted failure"};
        }
        const size_t n = std::min(capacity, item.bytes.size());
        std::copy(item.bytes.begin(), item.bytes.begin() + static_cast<long>(n), data);
        UsbResult r;
        r.length = n;
        return r;
    }

    UsbResult bulkOut(const uint8_t* data, size_t length, std::chrono::milliseconds) override
    {
        if (state_->unplugged) {
            return {Status::NoDevice, 0, "no device"};
        }
        state_->out.emplace_back(data, data + length);
        if (state_->echo) {
            state_->in.push_back({Bytes(data, data + length), Status::Ok});
        }
        UsbResult r;
        r.length = length;
        return r;
    }

private:
    UsbResult failure(uint8_t request)
    {
        if (state_->unplugged) {
            return {Status::NoDevice, 0, "no device"};
        }
        const auto found = state_->failures.find(request);
        return found == state_->failures.end() ? UsbResult{} : UsbResult{found->second, 0, "scripted failure"};
    }

    std::shared_ptr<FakeState> state_;
};

constexpr uint8_t kHostFormat = static_cast<uint8_t>(gsusb::Request::HostFormat);
constexpr uint8_t kBitTiming = static_cast<uint8_t>(gsusb::Request::BitTiming);
constexpr uint8_t kMode = static_cast<uint8_t>(gsusb::Request::Mode);
constexpr uint8_t kBtConst = static_cast<uint8_t>(gsusb::Request::BitTimingConst);
constexpr uint8_t kDeviceConfig = static_cast<uint8_t>(gsusb::Request::DeviceConfig);

// A candleLight on an STM32F0: one channel, 48 MHz, bxCAN's limits.
std::shared_ptr<FakeState> candleLight()
{
    auto state = std::make_shared<FakeState>();
    gsusb::DeviceConfig config;
    config.icount = 0;
    config.softwareVersion = 2;
    config.hardwareVersion = 1;
    state->replies[kDeviceConfig] = gsusb::encodeDeviceConfig(config);
    gsusb::BitTimingConst limits;
    limits.clockHz = 48'000'000;
    limits.tseg1Min = 1;
    limits.tseg1Max = 16;
    limits.tseg2Min = 1;
    limits.tseg2Max = 8;
    limits.sjwMax = 4;
    limits.brpMin = 1;
    limits.brpMax = 1024;
    limits.brpIncrement = 1;
    state->replies[kBtConst] = gsusb::encodeBitTimingConst(limits);
    return state;
}

std::unique_ptr<GsUsbTransport> openOn(const std::shared_ptr<FakeState>& state, uint32_t bitRate,
                                       TransportError& error)
{
    return GsUsbTransport::adopt(std::make_unique<FakeGsUsbDevice>(state), "gsusb:TEST", bitRate, error);
}

Bytes rxFrame(uint32_t canId, uint8_t dlc, Bytes data = {}, uint8_t flags = 0, uint8_t channel = 0)
{
    gsusb::HostFrame f;
    f.canId = canId;
    f.dlc = dlc;
    f.channel = channel;
    f.flags = flags;
    std::copy(data.begin(), data.begin() + static_cast<long>(std::min<size_t>(data.size(), 8)), f.data);
    return gsusb::encodeHostFrame(f);
}

Bytes le32(uint32_t v)
{
    return {static_cast<uint8_t>(v), static_cast<uint8_t>(v >> 8), static_cast<uint8_t>(v >> 16),
            static_cast<uint8_t>(v >> 24)};
}

Bytes concat(std::initializer_list<Bytes> parts)
{
    Bytes out;
    for (const Bytes& p : parts) {
        out.insert(out.end(), p.begin(), p.end());
    }
    return out;
}

TEST(GsUsbTransportTest, OpeningAndClosingSendLinuxsRequestsWithTheirBytes)
{
    auto state = candleLight();
    state->interfaceNumber = 0;
    {
        TransportError error;
        std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
        ASSERT_TRUE(transport) << error.message;
        EXPECT_EQ(transport->name(), "gsusb:TEST");
        EXPECT_EQ(transport->bitRate(), 500'000u);
        EXPECT_EQ(transport->deviceConfig().channels(), 1u);
        ASSERT_EQ(state->calls.size(), 5u);

        const ControlCall& hostFormat = state->calls[0];
        EXPECT_FALSE(hostFormat.in);
        EXPECT_EQ(hostFormat.request, kHostFormat);
        EXPECT_EQ(hostFormat.value, 1);
        EXPECT_EQ(hostFormat.index, 0) << "the interface number";
        EXPECT_EQ(hostFormat.data, (Bytes{0xEF, 0xBE, 0x00, 0x00}));

        const ControlCall& deviceConfig = state->calls[1];
        EXPECT_TRUE(deviceConfig.in);
        EXPECT_EQ(deviceConfig.request, kDeviceConfig);
        EXPECT_EQ(deviceConfig.value, 1);
        EXPECT_EQ(deviceConfig.index, 0);
        EXPECT_EQ(deviceConfig.length, 12u);

        const ControlCall& btConst = state->calls[2];
        EXPECT_TRUE(btConst.in);
        EXPECT_EQ(btConst.request, kBtConst);
        EXPECT_EQ(btConst.value, 0) << "channel 0";
        EXPECT_EQ(btConst.index, 0);
        EXPECT_EQ(btConst.length, 40u);

        const ControlCall& bitTiming = state->calls[3];
        EXPECT_FALSE(bitTiming.in);
        EXPECT_EQ(bitTiming.request, kBitTiming);
        EXPECT_EQ(bitTiming.value, 0);
        EXPECT_EQ(bitTiming.index, 0);
        // 500 kbit/s at 48 MHz: prescaler 6, 1 + 6 + 7 + 2 quanta, sjw 2.
        EXPECT_EQ(bitTiming.data, concat({le32(6), le32(7), le32(2), le32(2), le32(6)}));

        const ControlCall& start = state->calls[4];
        EXPECT_FALSE(start.in);
        EXPECT_EQ(start.request, kMode);
        EXPECT_EQ(start.value, 0);
        EXPECT_EQ(start.index, 0);
        EXPECT_EQ(start.data, concat({le32(1), le32(0)})) << "GS_CAN_MODE_START, no flags";
    }
    ASSERT_EQ(state->calls.size(), 6u);
    const ControlCall& reset = state->calls[5];
    EXPECT_FALSE(reset.in);
    EXPECT_EQ(reset.request, kMode);
    EXPECT_EQ(reset.value, 0);
    EXPECT_EQ(reset.data, Bytes(8, 0)) << "GS_CAN_MODE_RESET";
}

TEST(GsUsbTransportTest, TheInterfaceNumberIsTheIndexOfTheInterfaceRequests)
{
    auto state = candleLight();
    state->interfaceNumber = 2;
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 250'000, error);
    ASSERT_TRUE(transport) << error.message;
    EXPECT_EQ(state->calls[0].index, 2);
    EXPECT_EQ(state->calls[1].index, 2);
    EXPECT_EQ(state->calls[2].index, 0) << "channel requests keep wIndex 0";
    EXPECT_EQ(state->calls[3].data, concat({le32(6), le32(7), le32(2), le32(2), le32(12)}));
}

TEST(GsUsbTransportTest, AFrameGoesOutWithAnEchoIdAndItsEchoFreesIt)
{
    auto state = candleLight();
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 1'000'000, error);
    ASSERT_TRUE(transport) << error.message;
    const uint8_t bytes[] = {0x01, 0x02, 0x03};
    ASSERT_FALSE(transport->send(can::CanFrame::makeData(0x1ABCDEF0, can::IdFormat::Extended, bytes, 3).value(), 100ms));
    ASSERT_EQ(state->out.size(), 1u);
    EXPECT_EQ(state->out[0], concat({le32(0), le32(0x9ABCDEF0), Bytes{3, 0, 0, 0, 1, 2, 3, 0, 0, 0, 0, 0}}))
        << "echo id 0, CAN_EFF_FLAG, dlc 3, channel 0, flags 0, reserved 0";
    EXPECT_EQ(transport->framesInFlight(), 1u);
    // The echo is no frame of the bus: receive takes it and reports nothing.
    const Received r = transport->receive(20ms, error);
    EXPECT_EQ(r.kind, Received::Kind::Timeout);
    EXPECT_FALSE(error) << error.message;
    EXPECT_EQ(transport->framesInFlight(), 0u);

    // Remote and standard frames keep their flags.
    ASSERT_FALSE(transport->send(can::CanFrame::makeRemote(0x123, can::IdFormat::Standard, 2).value(), 100ms));
    EXPECT_EQ(Bytes(state->out[1].begin(), state->out[1].begin() + 9), concat({le32(0), le32(0x40000123), Bytes{2}}));
}

TEST(GsUsbTransportTest, TenFramesInFlightAtMostThenSendWaitsForAnEcho)
{
    auto state = candleLight();
    state->echo = false; // Nobody acknowledges: the adapter keeps them.
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    const can::CanFrame frame = can::CanFrame::makeData(0x100, can::IdFormat::Standard, nullptr, 0).value();
    for (uint32_t i = 0; i < gsusb::kMaxEchoIds; ++i) {
        ASSERT_FALSE(transport->send(frame, 100ms)) << i;
        EXPECT_EQ(state->out.back()[0], i) << "echo ids 0..9 in turn";
    }
    const TransportError refused = transport->send(frame, 30ms);
    EXPECT_EQ(refused.kind, TransportError::Kind::Refused);
    EXPECT_NE(refused.message.find("acknowledging"), std::string::npos) << refused.message;
    EXPECT_EQ(state->out.size(), gsusb::kMaxEchoIds);

    // A frame from the bus while waiting is kept for receive, and echo 3 frees its id.
    state->in.push_back({rxFrame(0x555, 1, {0x99}), Status::Ok});
    gsusb::HostFrame echo = gsusb::hostFrameFor(frame, 3, 0);
    state->in.push_back({gsusb::encodeHostFrame(echo), Status::Ok});
    ASSERT_FALSE(transport->send(frame, 100ms));
    EXPECT_EQ(state->out.back()[0], 3);
    const Received r = transport->receive(20ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame) << error.message;
    EXPECT_EQ(r.frame.id(), 0x555u);
    state->unplugged = true; // Spares closing its wait for echoes that will never come.
}

TEST(GsUsbTransportTest, FramesFromTheBusAreReceivedWithTheirFormat)
{
    auto state = candleLight();
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    state->in.push_back({rxFrame(0x7E8, 3, {0x02, 0x10, 0x01}), Status::Ok});
    state->in.push_back({rxFrame(CAN_EFF_FLAG | 0x18DAF100, 8, {1, 2, 3, 4, 5, 6, 7, 8}), Status::Ok});
    state->in.push_back({rxFrame(CAN_EFF_FLAG | CAN_RTR_FLAG | 0x1234, 4), Status::Ok});

    Received r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame) << error.message;
    EXPECT_EQ(r.frame.id(), 0x7E8u);
    EXPECT_FALSE(r.frame.isExtended());
    EXPECT_EQ(r.frame.length(), 3);
    EXPECT_EQ(r.frame.byte(1), 0x10);
    EXPECT_GT(r.timestamp.count(), 0);

    r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame);
    EXPECT_TRUE(r.frame.isExtended());
    EXPECT_EQ(r.frame.id(), 0x18DAF100u);
    EXPECT_EQ(r.frame.byte(7), 8);

    r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame);
    EXPECT_TRUE(r.frame.isRemote());
    EXPECT_EQ(r.frame.id(), 0x1234u);
    EXPECT_EQ(r.frame.length(), 4);

    r = transport->receive(10ms, error);
    EXPECT_EQ(r.kind, Received::Kind::Timeout);
    EXPECT_FALSE(error);
}

TEST(GsUsbTransportTest, ErrorFramesAndTheOverflowFlagBecomeBusEvents)
{
    auto state = candleLight();
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    state->in.push_back({rxFrame(CAN_ERR_FLAG | CAN_ERR_CRTL | CAN_ERR_CNT, CAN_ERR_DLC,
                                 {0, CAN_ERR_CRTL_RX_PASSIVE, 0, 0, 0, 0, 0, 128}),
                         Status::Ok});
    state->in.push_back({rxFrame(CAN_ERR_FLAG | CAN_ERR_BUSOFF | CAN_ERR_ACK, CAN_ERR_DLC), Status::Ok});
    state->in.push_back({rxFrame(0x321, 1, {7}, gsusb::kFrameFlagOverflow), Status::Ok});

    Received r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Event) << error.message;
    EXPECT_EQ(r.event, BusEventKind::ErrorPassive);
    EXPECT_NE(r.detail.find("rx errors 128"), std::string::npos) << r.detail;
    r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Event);
    EXPECT_EQ(r.event, BusEventKind::NoAcknowledge);
    r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Event);
    EXPECT_EQ(r.event, BusEventKind::BusOff);
    r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame);
    EXPECT_EQ(r.frame.id(), 0x321u);
    r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Event);
    EXPECT_EQ(r.event, BusEventKind::Overrun);
}

TEST(GsUsbTransportTest, ShortAndMalformedTransfersAreProtocolErrorsNotTheEnd)
{
    auto state = candleLight();
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    state->in.push_back({Bytes(10, 0xFF), Status::Ok});
    state->in.push_back({rxFrame(0x100, 12), Status::Ok});
    state->in.push_back({rxFrame(0x100, 0, {}, 0, 1), Status::Ok}); // A channel this adapter lacks.
    state->in.push_back({rxFrame(0x100, 8, {}, gsusb::kFrameFlagFd), Status::Ok});
    state->in.push_back({rxFrame(0x101, 1, {5}), Status::Ok});

    Received r = transport->receive(100ms, error);
    EXPECT_EQ(r.kind, Received::Kind::Timeout);
    EXPECT_EQ(error.kind, TransportError::Kind::Protocol);
    EXPECT_NE(error.message.find("10 bytes"), std::string::npos) << error.message;
    EXPECT_NE(error.message.find("gsusb:TEST"), std::string::npos) << error.message;
    for (const char* reason : {"data length code of 12", "channel 1", "CAN FD"}) {
        error = {};
        r = transport->receive(100ms, error);
        EXPECT_EQ(error.kind, TransportError::Kind::Protocol) << reason;
        EXPECT_NE(error.message.find(reason), std::string::npos) << error.message;
    }
    error = {};
    r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame) << error.message;
    EXPECT_EQ(r.frame.id(), 0x101u);
    EXPECT_EQ(transport->statistics().malformed, 4u);
}

TEST(GsUsbTransportTest, EchoesOfFramesWeNeverSentAreCountedAndDropped)
{
    auto state = candleLight();
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    gsusb::HostFrame stale;
    stale.echoId = 4;
    state->in.push_back({gsusb::encodeHostFrame(stale), Status::Ok});
    stale.echoId = 0x12345678;
    state->in.push_back({gsusb::encodeHostFrame(stale), Status::Ok});
    const Received r = transport->receive(20ms, error);
    EXPECT_EQ(r.kind, Received::Kind::Timeout);
    EXPECT_FALSE(error) << error.message;
    EXPECT_EQ(transport->statistics().unknownEchoes, 2u);
}

TEST(GsUsbTransportTest, AnAdapterUnpluggedMidTransferIsClosedForGood)
{
    auto state = candleLight();
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    state->in.push_back({rxFrame(0x100, 0), Status::Ok});
    state->in.push_back({{}, Status::NoDevice});
    Received r = transport->receive(100ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame) << error.message;
    r = transport->receive(100ms, error);
    EXPECT_EQ(r.kind, Received::Kind::Timeout);
    EXPECT_EQ(error.kind, TransportError::Kind::Closed);
    EXPECT_NE(error.message.find("the adapter was unplugged"), std::string::npos) << error.message;
    const TransportError sent = transport->send(can::CanFrame(), 100ms);
    EXPECT_EQ(sent.kind, TransportError::Kind::Closed);
    error = {};
    transport->receive(100ms, error);
    EXPECT_EQ(error.kind, TransportError::Kind::Closed);
    const size_t calls = state->calls.size();
    transport.reset();
    EXPECT_EQ(state->calls.size(), calls) << "nothing is sent to an adapter that is gone";
}

TEST(GsUsbTransportTest, AnAdapterUnpluggedWhileSendingIsClosed)
{
    auto state = candleLight();
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    state->unplugged = true;
    const TransportError sent = transport->send(can::CanFrame(), 100ms);
    EXPECT_EQ(sent.kind, TransportError::Kind::Closed);
    EXPECT_NE(sent.message.find("unplugged"), std::string::npos) << sent.message;
}

TEST(GsUsbTransportTest, ClosingLetsTheFramesInFlightReachTheBusFirst)
{
    auto state = candleLight();
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    ASSERT_FALSE(transport->send(can::CanFrame(), 100ms));
    ASSERT_FALSE(transport->send(can::CanFrame(), 100ms));
    EXPECT_EQ(state->in.size(), 2u) << "the two echoes wait in the adapter";
    transport.reset();
    EXPECT_TRUE(state->in.empty()) << "both echoes were read before the reset";
    EXPECT_EQ(state->calls.back().request, kMode);
    EXPECT_EQ(state->calls.back().data, Bytes(8, 0));
}

TEST(GsUsbTransportTest, DrainWaitsForEveryEchoAndSaysHowManyNeverCame)
{
    auto state = candleLight();
    state->echo = false; // The adapter keeps them until the test hands their echoes in.
    TransportError error;
    std::unique_ptr<GsUsbTransport> transport = openOn(state, 500'000, error);
    ASSERT_TRUE(transport) << error.message;
    const can::CanFrame frame = can::CanFrame::makeData(0x100, can::IdFormat::Standard, nullptr, 0).value();
    for (uint32_t i = 0; i < 3; ++i) {
        ASSERT_FALSE(transport->send(frame, 100ms));
    }
    // Two echoes come, with a frame of the bus between them; the third does not.
    state->in.push_back({gsusb::encodeHostFrame(gsusb::hostFrameFor(frame, 0, 0)), Status::Ok});
    state->in.push_back({rxFrame(0x555, 1, {0x99}), Status::Ok});
    state->in.push_back({gsusb::encodeHostFrame(gsusb::hostFrameFor(frame, 2, 0)), Status::Ok});
    const TransportError unconfirmed = transport->drain(30ms);
    EXPECT_EQ(unconfirmed.kind, TransportError::Kind::Refused);
    EXPECT_NE(unconfirmed.message.find("confirmed 1 frame not within 30 ms"), std::string::npos)
        << unconfirmed.message;
    EXPECT_EQ(transport->framesInFlight(), 1u);
    const Received r = transport->receive(20ms, error);
    ASSERT_EQ(r.kind, Received::Kind::Frame) << "the bus's frame is kept for receive";
    EXPECT_EQ(r.frame.id(), 0x555u);
    state->in.push_back({gsusb::encodeHostFrame(gsusb::hostFrameFor(frame, 1, 0)), Status::Ok});
    EXPECT_FALSE(transport->drain(30ms)) << "every frame confirmed";
    EXPECT_EQ(transport->framesInFlight(), 0u);
}

TEST(GsUsbTransportTest, OpeningFailuresSayWhichRequestAndWhy)
{
    {
        auto state = candleLight();
        state->failures[kHostFormat] = Status::Stall;
        TransportError error;
        EXPECT_FALSE(openOn(state, 500'000, error));
        EXPECT_EQ(error.kind, TransportError::Kind::Refused);
        EXPECT_NE(error.message.find("HOST_FORMAT"), std::string::npos) << error.message;
    }
    {
        auto state = candleLight();
        state->replies[kBtConst].resize(16);
        TransportError error;
        EXPECT_FALSE(openOn(state, 500'000, error));
        EXPECT_EQ(error.kind, TransportError::Kind::Protocol);
        EXPECT_NE(error.message.find("BT_CONST"), std::string::npos) << error.message;
        EXPECT_NE(error.message.find("16 bytes"), std::string::npos) << error.message;
    }
    {
        auto state = candleLight();
        state->replies[kDeviceConfig].clear();
        TransportError error;
        EXPECT_FALSE(openOn(state, 500'000, error));
        EXPECT_EQ(error.kind, TransportError::Kind::Protocol);
        EXPECT_NE(error.message.find("DEVICE_CONFIG"), std::string::npos) << error.message;
    }
    {
        auto state = candleLight();
        TransportError error;
        EXPECT_FALSE(openOn(state, 700'000, error));
        EXPECT_EQ(error.kind, TransportError::Kind::BadArgument);
        EXPECT_NE(error.message.find("700000"), std::string::npos) << error.message;
        EXPECT_EQ(state->calls.size(), 3u) << "no bit timing is sent for a rate that cannot be met";
    }
    {
        auto state = candleLight();
        state->failures[kMode] = Status::NoDevice;
        TransportError error;
        EXPECT_FALSE(openOn(state, 500'000, error));
        EXPECT_EQ(error.kind, TransportError::Kind::Closed);
        EXPECT_NE(error.message.find("unplugged"), std::string::npos) << error.message;
    }
    {
        auto state = candleLight();
        state->failures[kBitTiming] = Status::Timeout;
        TransportError error;
        EXPECT_FALSE(openOn(state, 500'000, error));
        EXPECT_EQ(error.kind, TransportError::Kind::Protocol);
        EXPECT_NE(error.message.find("BITTIMING"), std::string::npos) << error.message;
    }
}

TEST(GsUsbTransportTest, TheSpecFormsParse)
{
    TransportError error;
    std::optional<GsUsbSpec> spec = parseGsUsbSpec("gsusb", error);
    ASSERT_TRUE(spec) << error.message;
    EXPECT_EQ(spec->name, "gsusb");
    EXPECT_TRUE(spec->serial.empty());
    EXPECT_EQ(spec->bitRate, 500'000u);

    spec = parseGsUsbSpec("gsusb@250000", error);
    ASSERT_TRUE(spec) << error.message;
    EXPECT_TRUE(spec->serial.empty());
    EXPECT_EQ(spec->bitRate, 250'000u);

    spec = parseGsUsbSpec("gsusb:0037004A5346500B20363751", error);
    ASSERT_TRUE(spec) << error.message;
    EXPECT_EQ(spec->serial, "0037004A5346500B20363751");
    EXPECT_EQ(spec->name, "gsusb:0037004A5346500B20363751");
    EXPECT_EQ(spec->bitRate, 500'000u);

    spec = parseGsUsbSpec("gsusb:ABC-1@1000000", error);
    ASSERT_TRUE(spec) << error.message;
    EXPECT_EQ(spec->serial, "ABC-1");
    EXPECT_EQ(spec->name, "gsusb:ABC-1");
    EXPECT_EQ(spec->bitRate, 1'000'000u);
}

TEST(GsUsbTransportTest, BadSpecFormsAreBadArgumentsBeforeAnyUsb)
{
    for (const char* spec : {"gsusb:", "gsusb@", "gsusb@fast", "gsusb:@500000", "gsusb:ABC@", "gsusb:ABC@12x",
                             "gsusb@0", "gsusb@2000000", "gsusb:AB C", "gsusb:ABC@-5", "gsusb@500000@1"}) {
        TransportError error;
        EXPECT_FALSE(openTransport(spec, error)) << spec;
        EXPECT_EQ(error.kind, TransportError::Kind::BadArgument) << spec << ": " << error.message;
        EXPECT_NE(error.message.find("gsusb:<serial>"), std::string::npos) << error.message;
    }
    TransportError error;
    EXPECT_FALSE(parseGsUsbSpec("gsusbx", error));
    EXPECT_EQ(error.kind, TransportError::Kind::BadArgument);
    // The general list of forms names gs_usb too.
    EXPECT_FALSE(openTransport("gizmo:1", error));
    EXPECT_NE(error.message.find("gsusb"), std::string::npos) << error.message;
}

TEST(GsUsbTransportTest, AnAdapterThatIsNotThereIsNotAvailableAndNamed)
{
    // This machine has no adapter of that serial number (nor, usually, USB).
    TransportError error;
    EXPECT_FALSE(openTransport("gsusb:DCOS-NO-SUCH-ADAPTER", error));
    EXPECT_TRUE(error.kind == TransportError::Kind::NotAvailable || error.kind == TransportError::Kind::Open)
        << error.message;
    EXPECT_NE(error.message.find("DCOS-NO-SUCH-ADAPTER"), std::string::npos) << error.message;
}

} // namespace
