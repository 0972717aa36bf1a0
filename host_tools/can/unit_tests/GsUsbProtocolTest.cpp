// The gs_usb codec: the structures' exact bytes, host frames both ways,
// what an IN transfer means (frames, error frames, overflow, echoes), the
// refusals of short and malformed input, and the bit timing computed for
// the usual rates at the clocks of real adapters.
#include <hostcan/GsUsbProtocol.hpp>

#include <gtest/gtest.h>

#include <linux/can.h>
#include <linux/can/error.h>

#include <vector>

namespace {

using namespace hostcan::gsusb;
using hostcan::BusEventKind;
using hostcan::Received;
using Bytes = std::vector<uint8_t>;

// An STM32F0's bxCAN as candleLight reports it: 48 MHz, tseg1 1..16,
// tseg2 1..8, sjw up to 4, prescaler 1..1024.
BitTimingConst candleLight48()
{
    BitTimingConst c;
    c.feature = kFeatureListenOnly | kFeatureLoopBack | kFeatureHwTimestamp | kFeatureIdentify;
    c.clockHz = 48'000'000;
    c.tseg1Min = 1;
    c.tseg1Max = 16;
    c.tseg2Min = 1;
    c.tseg2Max = 8;
    c.sjwMax = 4;
    c.brpMin = 1;
    c.brpMax = 1024;
    c.brpIncrement = 1;
    return c;
}

// An FDCAN's nominal phase at 80 MHz: tseg1 1..256, tseg2 1..128, sjw up to
// 128, prescaler 1..512.
BitTimingConst fdcan80()
{
    BitTimingConst c;
    c.clockHz = 80'000'000;
    c.tseg1Min = 1;
    c.tseg1Max = 256;
    c.tseg2Min = 1;
    c.tseg2Max = 128;
    c.sjwMax = 128;
    c.brpMin = 1;
    c.brpMax = 512;
    c.brpIncrement = 1;
    return c;
}

Bytes rxFrame(uint32_t canId, uint8_t dlc, Bytes data = {}, uint8_t flags = 0, uint8_t channel = 0)
{
    HostFrame f;
    f.echoId = kEchoIdReceived;
    f.canId = canId;
    f.dlc = dlc;
    f.channel = channel;
    f.flags = flags;
    for (size_t i = 0; i < data.size() && i < 8; ++i) {
        f.data[i] = data[i];
    }
    return encodeHostFrame(f);
}

TEST(GsUsbProtocolTest, StructuresHaveTheirLittleEndianBytes)
{
    EXPECT_EQ(encodeHostConfig(), (Bytes{0xEF, 0xBE, 0x00, 0x00}));

    BitTiming t{1, 2, 3, 4, 0x01020304};
    EXPECT_EQ(encodeBitTiming(t), (Bytes{1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 4, 0, 0, 0, 0x04, 0x03, 0x02, 0x01}));
    const Bytes timingBytes = encodeBitTiming(t);
    EXPECT_EQ(decodeBitTiming(timingBytes.data(), timingBytes.size()).value(), t);

    DeviceMode start;
    start.mode = kModeStart;
    EXPECT_EQ(encodeDeviceMode(start), (Bytes{1, 0, 0, 0, 0, 0, 0, 0}));
    EXPECT_EQ(encodeDeviceMode(DeviceMode{}), (Bytes(8, 0)));

    const Bytes config = {0, 0, 0, 1, 0x02, 0, 0, 0, 0x01, 0, 0, 0};
    const Result<DeviceConfig> decoded = decodeDeviceConfig(config.data(), config.size());
    ASSERT_TRUE(decoded.ok()) << decoded.reason();
    EXPECT_EQ(decoded.value().channels(), 2u);
    EXPECT_EQ(decoded.value().softwareVersion, 2u);
    EXPECT_EQ(decoded.value().hardwareVersion, 1u);
    EXPECT_EQ(encodeDeviceConfig(decoded.value()), config);

    const Bytes limits = encodeBitTimingConst(candleLight48());
    ASSERT_EQ(limits.size(), BitTimingConst::kSize);
    EXPECT_EQ(Bytes(limits.begin() + 4, limits.begin() + 8), (Bytes{0x00, 0x6C, 0xDC, 0x02})) << "48000000 little-endian";
    const Result<BitTimingConst> back = decodeBitTimingConst(limits.data(), limits.size());
    ASSERT_TRUE(back.ok()) << back.reason();
    EXPECT_EQ(back.value().clockHz, 48'000'000u);
    EXPECT_EQ(back.value().tseg1Max, 16u);
    EXPECT_EQ(back.value().brpMax, 1024u);
    EXPECT_EQ(back.value().feature, candleLight48().feature);
}

TEST(GsUsbProtocolTest, ShortAndEmptyStructuresAreRefusedWithTheirLength)
{
    const Bytes eleven(11, 0);
    const Result<DeviceConfig> config = decodeDeviceConfig(eleven.data(), eleven.size());
    ASSERT_FALSE(config.ok());
    EXPECT_NE(config.reason().find("11 bytes"), std::string::npos) << config.reason();
    EXPECT_NE(config.reason().find("12"), std::string::npos) << config.reason();
    EXPECT_FALSE(decodeDeviceConfig(nullptr, 12).ok());
    EXPECT_FALSE(decodeBitTimingConst(eleven.data(), eleven.size()).ok());
    EXPECT_FALSE(decodeBitTiming(eleven.data(), 19).ok());
    EXPECT_FALSE(decodeDeviceMode(eleven.data(), 7).ok());

    BitTimingConst noClock = candleLight48();
    noClock.clockHz = 0;
    Bytes bytes = encodeBitTimingConst(noClock);
    EXPECT_FALSE(decodeBitTimingConst(bytes.data(), bytes.size()).ok());
    BitTimingConst empty = candleLight48();
    empty.tseg1Min = 17;
    bytes = encodeBitTimingConst(empty);
    const Result<BitTimingConst> refused = decodeBitTimingConst(bytes.data(), bytes.size());
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.reason().find("tseg1 17..16"), std::string::npos) << refused.reason();
    BitTimingConst anyStep = candleLight48();
    anyStep.brpIncrement = 0;
    bytes = encodeBitTimingConst(anyStep);
    EXPECT_EQ(decodeBitTimingConst(bytes.data(), bytes.size()).value().brpIncrement, 1u);
}

TEST(GsUsbProtocolTest, HostFramesGoBothWays)
{
    const uint8_t payload[] = {0xDE, 0xAD, 0xBE, 0xEF};
    const can::CanFrame frame = can::CanFrame::makeData(0x1ABCDEF0, can::IdFormat::Extended, payload, 4).value();
    const Bytes bytes = encodeHostFrame(hostFrameFor(frame, 7, 0));
    EXPECT_EQ(bytes, (Bytes{7, 0, 0, 0, 0xF0, 0xDE, 0xBC, 0x9A, 4, 0, 0, 0, 0xDE, 0xAD, 0xBE, 0xEF, 0, 0, 0, 0}))
        << "echo id 7, can_id 0x1ABCDEF0 with CAN_EFF_FLAG, dlc 4, channel 0, flags 0";
    const Result<HostFrame> back = decodeHostFrame(bytes.data(), bytes.size(), false);
    ASSERT_TRUE(back.ok()) << back.reason();
    EXPECT_EQ(back.value().echoId, 7u);
    EXPECT_EQ(canFrameOf(back.value()).value(), frame);

    const can::CanFrame remote = can::CanFrame::makeRemote(0x123, can::IdFormat::Standard, 3).value();
    const Bytes remoteBytes = encodeHostFrame(hostFrameFor(remote, 0, 0));
    EXPECT_EQ(Bytes(remoteBytes.begin() + 4, remoteBytes.begin() + 9), (Bytes{0x23, 0x01, 0x00, 0x40, 3}))
        << "CAN_RTR_FLAG and the length asked for";
    EXPECT_EQ(canFrameOf(decodeHostFrame(remoteBytes.data(), remoteBytes.size(), false).value()).value(), remote);

    HostFrame timed = hostFrameFor(frame, kEchoIdReceived, 0);
    timed.hasTimestamp = true;
    timed.timestampUs = 0x11223344;
    const Bytes timedBytes = encodeHostFrame(timed);
    ASSERT_EQ(timedBytes.size(), kHostFrameTimestampedSize);
    EXPECT_FALSE(decodeHostFrame(timedBytes.data(), 20, true).ok()) << "a timestamped channel needs 24 bytes";
    EXPECT_EQ(decodeHostFrame(timedBytes.data(), timedBytes.size(), true).value().timestampUs, 0x11223344u);
}

TEST(GsUsbProtocolTest, AReceivedTransferBecomesAFrame)
{
    const Bytes standard = rxFrame(0x7FF, 2, {0xAA, 0xBB});
    Result<InTransfer> in = decodeInTransfer(standard.data(), standard.size(), false, 1);
    ASSERT_TRUE(in.ok()) << in.reason();
    EXPECT_FALSE(in.value().isEcho);
    ASSERT_EQ(in.value().received.size(), 1u);
    const Received& r = in.value().received[0];
    EXPECT_EQ(r.kind, Received::Kind::Frame);
    EXPECT_EQ(r.frame.id(), 0x7FFu);
    EXPECT_FALSE(r.frame.isExtended());
    EXPECT_EQ(r.frame.length(), 2);
    EXPECT_EQ(r.frame.byte(1), 0xBB);

    const Bytes extendedRemote = rxFrame(CAN_EFF_FLAG | CAN_RTR_FLAG | 0x18DA00F1, 8);
    in = decodeInTransfer(extendedRemote.data(), extendedRemote.size(), false, 1);
    ASSERT_TRUE(in.ok()) << in.reason();
    EXPECT_TRUE(in.value().received[0].frame.isExtended());
    EXPECT_TRUE(in.value().received[0].frame.isRemote());
    EXPECT_EQ(in.value().received[0].frame.id(), 0x18DA00F1u);
    EXPECT_EQ(in.value().received[0].frame.length(), 8);

    // A device that pads its packets to 64 bytes is read all the same.
    Bytes padded = standard;
    padded.resize(64, 0xEE);
    EXPECT_TRUE(decodeInTransfer(padded.data(), padded.size(), false, 1).ok());
}

TEST(GsUsbProtocolTest, EchoesCarryTheirIdAndNoFrame)
{
    HostFrame echo;
    echo.echoId = 3;
    echo.canId = 0x123;
    const Bytes bytes = encodeHostFrame(echo);
    const Result<InTransfer> in = decodeInTransfer(bytes.data(), bytes.size(), false, 1);
    ASSERT_TRUE(in.ok()) << in.reason();
    EXPECT_TRUE(in.value().isEcho);
    EXPECT_EQ(in.value().echoId, 3u);
    EXPECT_TRUE(in.value().received.empty());
}

TEST(GsUsbProtocolTest, ErrorFramesBecomeBusEvents)
{
    Bytes bytes = rxFrame(CAN_ERR_FLAG | CAN_ERR_CRTL | CAN_ERR_CNT, CAN_ERR_DLC, {0, CAN_ERR_CRTL_TX_PASSIVE, 0, 0, 0, 0, 130, 5});
    Result<InTransfer> in = decodeInTransfer(bytes.data(), bytes.size(), false, 1);
    ASSERT_TRUE(in.ok()) << in.reason();
    ASSERT_EQ(in.value().received.size(), 1u);
    EXPECT_EQ(in.value().received[0].kind, Received::Kind::Event);
    EXPECT_EQ(in.value().received[0].event, BusEventKind::ErrorPassive);
    EXPECT_NE(in.value().received[0].detail.find("tx errors 130"), std::string::npos);

    bytes = rxFrame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, CAN_ERR_DLC);
    in = decodeInTransfer(bytes.data(), bytes.size(), false, 1);
    ASSERT_TRUE(in.ok());
    EXPECT_EQ(in.value().received.at(0).event, BusEventKind::BusOff);

    bytes = rxFrame(CAN_ERR_FLAG | CAN_ERR_CRTL, CAN_ERR_DLC, {0, CAN_ERR_CRTL_RX_WARNING});
    EXPECT_EQ(decodeInTransfer(bytes.data(), bytes.size(), false, 1).value().received.at(0).event,
              BusEventKind::ErrorWarning);

    // An error frame whose classes we do not know is still reported.
    bytes = rxFrame(CAN_ERR_FLAG, CAN_ERR_DLC);
    in = decodeInTransfer(bytes.data(), bytes.size(), false, 1);
    ASSERT_TRUE(in.ok());
    EXPECT_EQ(in.value().received.at(0).event, BusEventKind::BusError);
}

TEST(GsUsbProtocolTest, TheOverflowFlagIsAnOverrunAfterTheFrame)
{
    const Bytes bytes = rxFrame(0x100, 1, {0x42}, kFrameFlagOverflow);
    const Result<InTransfer> in = decodeInTransfer(bytes.data(), bytes.size(), false, 1);
    ASSERT_TRUE(in.ok()) << in.reason();
    ASSERT_EQ(in.value().received.size(), 2u);
    EXPECT_EQ(in.value().received[0].kind, Received::Kind::Frame);
    EXPECT_EQ(in.value().received[1].kind, Received::Kind::Event);
    EXPECT_EQ(in.value().received[1].event, BusEventKind::Overrun);
}

TEST(GsUsbProtocolTest, ShortAndMalformedTransfersAreRefusedWithTheReason)
{
    const Bytes good = rxFrame(0x100, 1, {1});
    for (size_t size : {size_t{0}, size_t{1}, size_t{12}, size_t{19}}) {
        const Result<InTransfer> in = decodeInTransfer(good.data(), size, false, 1);
        ASSERT_FALSE(in.ok()) << size;
        EXPECT_NE(in.reason().find(std::to_string(size) + " bytes"), std::string::npos) << in.reason();
    }
    EXPECT_FALSE(decodeInTransfer(nullptr, 20, false, 1).ok());

    Bytes nine = rxFrame(0x100, 9);
    Result<InTransfer> in = decodeInTransfer(nine.data(), nine.size(), false, 1);
    ASSERT_FALSE(in.ok());
    EXPECT_NE(in.reason().find("data length code of 9"), std::string::npos) << in.reason();

    Bytes wide = rxFrame(0x800, 0);
    in = decodeInTransfer(wide.data(), wide.size(), false, 1);
    ASSERT_FALSE(in.ok());
    EXPECT_NE(in.reason().find("11 bits"), std::string::npos) << in.reason();

    Bytes fd = rxFrame(0x100, 8, {}, kFrameFlagFd);
    in = decodeInTransfer(fd.data(), fd.size(), false, 1);
    ASSERT_FALSE(in.ok());
    EXPECT_NE(in.reason().find("CAN FD"), std::string::npos) << in.reason();

    Bytes channel = rxFrame(0x100, 0, {}, 0, 2);
    in = decodeInTransfer(channel.data(), channel.size(), false, 2);
    ASSERT_FALSE(in.ok());
    EXPECT_NE(in.reason().find("channel 2"), std::string::npos) << in.reason();
    EXPECT_TRUE(decodeInTransfer(channel.data(), channel.size(), false, 3).ok());
}

struct Expected {
    uint32_t bitRate;
    uint32_t brp;
    uint32_t propSeg;
    uint32_t phaseSeg1;
    uint32_t phaseSeg2;
    uint32_t sjw;
};

TEST(GsUsbProtocolTest, BitTimingAt48MHzMeetsTheUsualRatesAt87Point5Percent)
{
    // 16 quanta per bit (6 + 7 + 2 after the sync quantum): sample point 14/16.
    for (const Expected& e : {Expected{125'000, 24, 6, 7, 2, 2}, Expected{250'000, 12, 6, 7, 2, 2},
                              Expected{500'000, 6, 6, 7, 2, 2}, Expected{1'000'000, 3, 6, 7, 2, 2}}) {
        const Result<BitTimingChoice> choice = computeBitTiming(e.bitRate, candleLight48());
        ASSERT_TRUE(choice.ok()) << e.bitRate << ": " << choice.reason();
        EXPECT_EQ(choice.value().timing, (BitTiming{e.propSeg, e.phaseSeg1, e.phaseSeg2, e.sjw, e.brp})) << e.bitRate;
        EXPECT_EQ(choice.value().bitRate, e.bitRate);
        EXPECT_EQ(choice.value().quanta, 16u);
        EXPECT_EQ(choice.value().samplePointPermille, 875u);
    }
}

TEST(GsUsbProtocolTest, BitTimingAt80MHzTakesTheMostQuantaTheSegmentsHold)
{
    for (const Expected& e : {Expected{125'000, 4, 69, 70, 20, 20}, Expected{250'000, 2, 69, 70, 20, 20},
                              Expected{500'000, 1, 69, 70, 20, 20}, Expected{1'000'000, 1, 34, 35, 10, 10}}) {
        const Result<BitTimingChoice> choice = computeBitTiming(e.bitRate, fdcan80());
        ASSERT_TRUE(choice.ok()) << e.bitRate << ": " << choice.reason();
        EXPECT_EQ(choice.value().timing, (BitTiming{e.propSeg, e.phaseSeg1, e.phaseSeg2, e.sjw, e.brp})) << e.bitRate;
        EXPECT_EQ(choice.value().bitRate, e.bitRate);
        EXPECT_EQ(choice.value().samplePointPermille, 875u);
    }
    // The same 80 MHz through a bxCAN's small segments: 16 quanta again.
    BitTimingConst small = candleLight48();
    small.clockHz = 80'000'000;
    const Result<BitTimingChoice> choice = computeBitTiming(500'000, small);
    ASSERT_TRUE(choice.ok()) << choice.reason();
    EXPECT_EQ(choice.value().timing, (BitTiming{6, 7, 2, 2, 10}));
}

TEST(GsUsbProtocolTest, BitTimingKeepsToThePrescalerStepAndTheSjwLimit)
{
    BitTimingConst even = candleLight48();
    even.brpMin = 2;
    even.brpIncrement = 2;
    even.sjwMax = 1;
    const Result<BitTimingChoice> choice = computeBitTiming(1'000'000, even);
    ASSERT_TRUE(choice.ok()) << choice.reason();
    EXPECT_EQ(choice.value().timing.brp % 2, 0u);
    EXPECT_EQ(choice.value().timing.sjw, 1u);
    EXPECT_EQ(choice.value().bitRate, 1'000'000u);
    const BitTiming& t = choice.value().timing;
    EXPECT_EQ(choice.value().quanta, 1 + t.propSeg + t.phaseSeg1 + t.phaseSeg2);
}

TEST(GsUsbProtocolTest, EveryChosenTimingIsWithinTheLimitsAndTheRate)
{
    for (const BitTimingConst& limits : {candleLight48(), fdcan80()}) {
        for (uint32_t rate : {10'000u, 20'000u, 50'000u, 83'333u, 100'000u, 800'000u}) {
            const Result<BitTimingChoice> choice = computeBitTiming(rate, limits);
            ASSERT_TRUE(choice.ok()) << rate << ": " << choice.reason();
            const BitTiming& t = choice.value().timing;
            const uint32_t tseg1 = t.propSeg + t.phaseSeg1;
            EXPECT_GE(tseg1, limits.tseg1Min);
            EXPECT_LE(tseg1, limits.tseg1Max);
            EXPECT_GE(t.phaseSeg2, limits.tseg2Min);
            EXPECT_LE(t.phaseSeg2, limits.tseg2Max);
            EXPECT_LE(t.sjw, std::min({limits.sjwMax, t.phaseSeg1, t.phaseSeg2}));
            EXPECT_GE(t.brp, limits.brpMin);
            EXPECT_LE(t.brp, limits.brpMax);
            const double made = double(limits.clockHz) / (double(t.brp) * (1 + tseg1 + t.phaseSeg2));
            EXPECT_NEAR(made, rate, rate * 0.001) << rate;
        }
    }
}

TEST(GsUsbProtocolTest, AnImpossibleRateIsRefusedSayingWhatTheAdapterOffers)
{
    // 48 MHz / 700 kbit/s is 68.57 clocks per bit: no whole number of quanta is within 0.1 %.
    Result<BitTimingChoice> choice = computeBitTiming(700'000, candleLight48());
    ASSERT_FALSE(choice.ok());
    EXPECT_NE(choice.reason().find("700000 bit/s"), std::string::npos) << choice.reason();
    EXPECT_NE(choice.reason().find("48000000 Hz"), std::string::npos) << choice.reason();
    // 1 kbit/s at 48 MHz needs a prescaler above 1024.
    EXPECT_FALSE(computeBitTiming(1'000, candleLight48()).ok());
    EXPECT_TRUE(computeBitTiming(1'000, fdcan80()).ok()) << "80 MHz / 1 kbit/s: a prescaler of 500, 160 quanta";
    // Outside classic CAN's rates, whatever the clock.
    choice = computeBitTiming(2'000'000, fdcan80());
    ASSERT_FALSE(choice.ok());
    EXPECT_NE(choice.reason().find("2000000"), std::string::npos);
    EXPECT_FALSE(computeBitTiming(0, fdcan80()).ok());
    BitTimingConst none = fdcan80();
    none.clockHz = 0;
    EXPECT_FALSE(computeBitTiming(500'000, none).ok());
}

TEST(GsUsbProtocolTest, AbsurdLimitsEndQuickly)
{
    BitTimingConst wide;
    wide.clockHz = 0xFFFFFFFF;
    wide.tseg1Min = 0;
    wide.tseg1Max = 0xFFFFFFFF;
    wide.tseg2Min = 0;
    wide.tseg2Max = 0xFFFFFFFF;
    wide.sjwMax = 0xFFFFFFFF;
    wide.brpMin = 0;
    wide.brpMax = 0xFFFFFFFF;
    wide.brpIncrement = 1;
    for (uint32_t rate : {kMinBitRate, 125'000u, kMaxBitRate}) {
        const Result<BitTimingChoice> choice = computeBitTiming(rate, wide);
        if (choice.ok()) {
            EXPECT_GE(choice.value().timing.brp, 1u);
            EXPECT_GE(choice.value().timing.phaseSeg2, 1u);
        }
    }
}

} // namespace
