// IsoTpReceiver: assembling messages, the flow control it answers with, and
// every frame it must ignore or end a reception on.
#include <can/IsoTpReceiver.hpp>

#include "IsoTpTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using can::CanFrame;
using can::IdFormat;
using can::IsoTpConfig;
using can::IsoTpReceiver;
using can::IsoTpStep;
using can::LinkError;
using namespace isotp_test;

using Bytes = std::vector<uint8_t>;

class IsoTpReceiverTest : public ::testing::Test {
protected:
    IsoTpReceiver make(const IsoTpConfig& c = config(), size_t capacity = 4095)
    {
        auto receiver = IsoTpReceiver::create(c, buffer_, capacity);
        EXPECT_TRUE(receiver.ok());
        return receiver.value();
    }

    Bytes received(const IsoTpStep& step) const { return Bytes(buffer_, buffer_ + step.length); }

    // Feeds a whole segmented message as the peer would send it (without
    // waiting for flow control) and returns the last step.
    static IsoTpStep feedMessage(IsoTpReceiver& receiver, const Bytes& message, uint64_t now = 0,
                                 int* flowControls = nullptr)
    {
        IsoTpStep step = receiver.onFrame(
            incoming({static_cast<uint8_t>(0x10 | (message.size() >> 8)), static_cast<uint8_t>(message.size()),
                      message[0], message[1], message[2], message[3], message[4], message[5]}),
            now);
        EXPECT_TRUE(step.transmit);
        size_t offset = 6;
        uint8_t sequence = 1;
        while (offset < message.size()) {
            const size_t count = std::min<size_t>(7, message.size() - offset);
            uint8_t bytes[8] = {static_cast<uint8_t>(0x20 | sequence)};
            for (size_t i = 0; i < count; ++i) {
                bytes[1 + i] = message[offset + i];
            }
            step = receiver.onFrame(
                CanFrame::makeData(kRxId, IdFormat::Extended, bytes, static_cast<uint8_t>(1 + count)).value(), now);
            EXPECT_EQ(step.rejected, LinkError::Ok);
            EXPECT_EQ(step.aborted, LinkError::Ok);
            if (flowControls != nullptr && step.transmit) {
                ++*flowControls;
            }
            offset += count;
            sequence = (sequence + 1) % 16;
        }
        return step;
    }

    uint8_t buffer_[4095] = {};
};

TEST_F(IsoTpReceiverTest, SingleFrame)
{
    IsoTpReceiver receiver = make();
    const IsoTpStep step = receiver.onFrame(incoming({0x03, 0xAA, 0xBB, 0xCC}), 0);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.length, 3);
    EXPECT_FALSE(step.transmit);
    EXPECT_EQ(received(step), (Bytes{0xAA, 0xBB, 0xCC}));
    EXPECT_TRUE(receiver.idle());
    EXPECT_EQ(receiver.buffer(), buffer_);
}

TEST_F(IsoTpReceiverTest, PaddedSingleFrame)
{
    IsoTpReceiver receiver = make();
    const IsoTpStep step = receiver.onFrame(incoming({0x02, 0x11, 0x22, 0xCC, 0xCC, 0xCC, 0xCC, 0xCC}), 0);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(received(step), (Bytes{0x11, 0x22}));
}

TEST_F(IsoTpReceiverTest, SingleFrameLengthErrors)
{
    IsoTpReceiver receiver = make();
    // SF_DL 0, SF_DL above 7, and SF_DL beyond the frame's data are ignored.
    EXPECT_EQ(receiver.onFrame(incoming({0x00, 1, 2}), 0).rejected, LinkError::InvalidSingleFrameLength);
    for (uint8_t length = 8; length <= 15; ++length) {
        EXPECT_EQ(receiver.onFrame(incoming({length, 1, 2, 3, 4, 5, 6, 7}), 0).rejected,
                  LinkError::InvalidSingleFrameLength)
            << int(length);
    }
    EXPECT_EQ(receiver.onFrame(incoming({0x05, 1, 2, 3, 4}), 0).rejected, LinkError::InvalidSingleFrameLength);
    EXPECT_EQ(receiver.onFrame(incoming({0x01}), 0).rejected, LinkError::InvalidSingleFrameLength);
    EXPECT_FALSE(receiver.onFrame(incoming({0x01}), 0).completed);
}

TEST_F(IsoTpReceiverTest, SingleFrameLongerThanTheBuffer)
{
    IsoTpReceiver receiver = make(config(), 4);
    const IsoTpStep step = receiver.onFrame(incoming({0x05, 1, 2, 3, 4, 5}), 0);
    EXPECT_EQ(step.rejected, LinkError::BufferOverflow);
    EXPECT_FALSE(step.completed);
    EXPECT_FALSE(step.transmit) << "a single frame has no flow control to refuse it with";
    EXPECT_TRUE(receiver.onFrame(incoming({0x04, 1, 2, 3, 4}), 0).completed);
}

TEST_F(IsoTpReceiverTest, TenBytesAnsweredAsLinuxIsotprecvAnswers)
{
    IsoTpReceiver receiver = make();
    const IsoTpStep first = receiver.onFrame(incoming({0x10, 0x0A, 1, 2, 3, 4, 5, 6}), 0);
    ASSERT_TRUE(first.transmit);
    EXPECT_FALSE(first.completed);
    // isotprecv's default flow control: CTS, BS 0, STmin 0, in a 3-byte frame.
    EXPECT_EQ(first.frame.id(), kTxId);
    EXPECT_EQ(bytesOf(first.frame), (Bytes{0x30, 0x00, 0x00}));
    EXPECT_FALSE(receiver.idle());

    const IsoTpStep last = receiver.onFrame(incoming({0x21, 7, 8, 9, 10}), 1);
    EXPECT_TRUE(last.completed);
    EXPECT_FALSE(last.transmit);
    EXPECT_EQ(received(last), (Bytes{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
    EXPECT_TRUE(receiver.idle());
}

TEST_F(IsoTpReceiverTest, PaddedLastConsecutiveFrameIsAccepted)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x09, 1, 2, 3, 4, 5, 6}), 0);
    const IsoTpStep last = receiver.onFrame(incoming({0x21, 7, 8, 9, 0xCC, 0xCC, 0xCC, 0xCC}), 1);
    EXPECT_TRUE(last.completed);
    EXPECT_EQ(received(last), (Bytes{1, 2, 3, 4, 5, 6, 7, 8, 9}));
}

TEST_F(IsoTpReceiverTest, SequenceNumberWrapsPastSixteenFrames)
{
    IsoTpReceiver receiver = make();
    const Bytes message = pattern(6 + 7 * 40); // 40 CFs: SN 1..15, 0..15, 0..8
    const IsoTpStep last = feedMessage(receiver, message);
    EXPECT_TRUE(last.completed);
    EXPECT_EQ(received(last), message);
}

TEST_F(IsoTpReceiverTest, LongestMessage)
{
    IsoTpReceiver receiver = make();
    const Bytes message = pattern(4095);
    const IsoTpStep last = feedMessage(receiver, message);
    EXPECT_TRUE(last.completed);
    EXPECT_EQ(last.length, 4095);
    EXPECT_EQ(received(last), message);
}

TEST_F(IsoTpReceiverTest, MessageLongerThanTheBufferIsRefusedWithOverflow)
{
    IsoTpReceiver receiver = make(config(), 100);
    const IsoTpStep step = receiver.onFrame(incoming({0x10, 101, 1, 2, 3, 4, 5, 6}), 0);
    EXPECT_EQ(step.rejected, LinkError::BufferOverflow);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(bytesOf(step.frame), (Bytes{0x32, 0x00, 0x00}));
    EXPECT_TRUE(receiver.idle());
    EXPECT_EQ(receiver.onFrame(incoming({0x21, 7}), 1).rejected, LinkError::NotExpected);

    const IsoTpStep fits = receiver.onFrame(incoming({0x10, 100, 1, 2, 3, 4, 5, 6}), 2);
    EXPECT_EQ(bytesOf(fits.frame), (Bytes{0x30, 0x00, 0x00}));
}

TEST_F(IsoTpReceiverTest, FirstFrameErrorsAreIgnored)
{
    IsoTpReceiver receiver = make();
    // Shorter than the 8 bytes a first frame fills.
    EXPECT_EQ(receiver.onFrame(incoming({0x10, 0x0A, 1, 2, 3, 4, 5}), 0).rejected, LinkError::InvalidFirstFrame);
    // FF_DL 1..7 would have fitted a single frame.
    for (uint8_t length = 1; length <= 7; ++length) {
        const IsoTpStep step = receiver.onFrame(incoming({0x10, length, 1, 2, 3, 4, 5, 6}), 0);
        EXPECT_EQ(step.rejected, LinkError::InvalidFirstFrame) << int(length);
        EXPECT_FALSE(step.transmit);
    }
    // The 32-bit escape announcing a length that 12 bits hold.
    EXPECT_EQ(receiver.onFrame(incoming({0x10, 0x00, 0x00, 0x00, 0x0F, 0xFF, 1, 2}), 0).rejected,
              LinkError::InvalidFirstFrame);
    EXPECT_EQ(receiver.onFrame(incoming({0x10, 0x00, 0x00, 0x00, 0x00, 0x00, 1, 2}), 0).rejected,
              LinkError::InvalidFirstFrame);
    EXPECT_TRUE(receiver.idle());
}

TEST_F(IsoTpReceiverTest, EscapedLengthAboveFourKilobytesOverflows)
{
    IsoTpReceiver receiver = make();
    const IsoTpStep step = receiver.onFrame(incoming({0x10, 0x00, 0x00, 0x00, 0x10, 0x00, 1, 2}), 0);
    EXPECT_EQ(step.rejected, LinkError::BufferOverflow);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(step.frame.byte(0), 0x32);
}

TEST_F(IsoTpReceiverTest, BlockSizeAndSeparationTimeAreAnnounced)
{
    IsoTpConfig c = config();
    c.blockSize = 3;
    c.separationTimeNs = 300000; // 300 us: STmin 0xF3
    IsoTpReceiver receiver = make(c);
    const Bytes message = pattern(6 + 7 * 7); // 7 CFs: FC after 3, after 6, none after the last
    const IsoTpStep first = receiver.onFrame(
        incoming({0x10, static_cast<uint8_t>(message.size()), message[0], message[1], message[2], message[3],
                  message[4], message[5]}),
        0);
    EXPECT_EQ(bytesOf(first.frame), (Bytes{0x30, 0x03, 0xF3}));
    int flowControls = 0;
    size_t offset = 6;
    for (uint8_t sn = 1; sn <= 7; ++sn) {
        uint8_t bytes[8] = {static_cast<uint8_t>(0x20 | sn)};
        for (int i = 0; i < 7; ++i) {
            bytes[1 + i] = message[offset + i];
        }
        offset += 7;
        const IsoTpStep step = receiver.onFrame(CanFrame::makeData(kRxId, IdFormat::Extended, bytes, 8).value(), sn);
        if (step.transmit) {
            ++flowControls;
            EXPECT_TRUE(sn == 3 || sn == 6) << int(sn);
            EXPECT_EQ(bytesOf(step.frame), (Bytes{0x30, 0x03, 0xF3}));
        }
        EXPECT_EQ(step.completed, sn == 7);
    }
    EXPECT_EQ(flowControls, 2);
}

TEST_F(IsoTpReceiverTest, SeparationTimeInMilliseconds)
{
    IsoTpConfig c = config();
    c.separationTimeNs = 5 * kMillisecond;
    IsoTpReceiver receiver = make(c);
    EXPECT_EQ(bytesOf(receiver.onFrame(incoming({0x10, 0x14, 1, 2, 3, 4, 5, 6}), 0).frame),
              (Bytes{0x30, 0x00, 0x05}));
}

TEST_F(IsoTpReceiverTest, PaddedFlowControl)
{
    IsoTpConfig c = config();
    c.padding.enabled = true;
    c.padding.value = 0xAA;
    IsoTpReceiver receiver = make(c);
    EXPECT_EQ(bytesOf(receiver.onFrame(incoming({0x10, 0x14, 1, 2, 3, 4, 5, 6}), 0).frame),
              (Bytes{0x30, 0x00, 0x00, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA}));
}

TEST_F(IsoTpReceiverTest, ConsecutiveFrameWithoutFirstFrame)
{
    IsoTpReceiver receiver = make();
    const IsoTpStep step = receiver.onFrame(incoming({0x21, 1, 2, 3}), 0);
    EXPECT_EQ(step.rejected, LinkError::NotExpected);
    EXPECT_FALSE(step.completed);
}

TEST_F(IsoTpReceiverTest, WrongSequenceNumberEndsTheReception)
{
    for (const uint8_t sn : {uint8_t{0}, uint8_t{2}, uint8_t{15}}) {
        IsoTpReceiver receiver = make();
        receiver.onFrame(incoming({0x10, 0x14, 1, 2, 3, 4, 5, 6}), 0);
        const IsoTpStep step = receiver.onFrame(incoming({static_cast<uint8_t>(0x20 | sn), 1, 2, 3, 4, 5, 6, 7}), 1);
        EXPECT_EQ(step.aborted, LinkError::WrongSequenceNumber) << int(sn);
        EXPECT_FALSE(step.completed);
        EXPECT_TRUE(receiver.idle());
    }
}

TEST_F(IsoTpReceiverTest, DuplicatedConsecutiveFrame)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x20, 1, 2, 3, 4, 5, 6}), 0);
    EXPECT_EQ(receiver.onFrame(incoming({0x21, 1, 2, 3, 4, 5, 6, 7}), 1).aborted, LinkError::Ok);
    const IsoTpStep again = receiver.onFrame(incoming({0x21, 1, 2, 3, 4, 5, 6, 7}), 2);
    EXPECT_EQ(again.aborted, LinkError::WrongSequenceNumber);
    EXPECT_TRUE(receiver.idle());
    EXPECT_EQ(receiver.onFrame(incoming({0x22, 1, 2, 3, 4, 5, 6, 7}), 3).rejected, LinkError::NotExpected);
}

TEST_F(IsoTpReceiverTest, OutOfOrderConsecutiveFrame)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x20, 1, 2, 3, 4, 5, 6}), 0);
    receiver.onFrame(incoming({0x21, 1, 2, 3, 4, 5, 6, 7}), 1);
    EXPECT_EQ(receiver.onFrame(incoming({0x23, 1, 2, 3, 4, 5, 6, 7}), 2).aborted, LinkError::WrongSequenceNumber);
}

TEST_F(IsoTpReceiverTest, ShortConsecutiveFrameIsIgnored)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x14, 1, 2, 3, 4, 5, 6}), 0);
    // Not the last CF, so it must carry 7 bytes; this one carries 6.
    const IsoTpStep step = receiver.onFrame(incoming({0x21, 7, 8, 9, 10, 11, 12}), 1);
    EXPECT_EQ(step.rejected, LinkError::ShortFrame);
    EXPECT_EQ(step.aborted, LinkError::Ok);
    EXPECT_FALSE(receiver.idle());
    EXPECT_EQ(receiver.onFrame(incoming({0x21}), 1).rejected, LinkError::ShortFrame);
    // The reception goes on with the frame as it should have been.
    receiver.onFrame(incoming({0x21, 7, 8, 9, 10, 11, 12, 13}), 2);
    const IsoTpStep last = receiver.onFrame(incoming({0x22, 14, 15, 16, 17, 18, 19, 20}), 3);
    ASSERT_TRUE(last.completed);
    EXPECT_EQ(received(last), (Bytes{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20}));
}

TEST_F(IsoTpReceiverTest, ShortLastConsecutiveFrameIsIgnored)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x0A, 1, 2, 3, 4, 5, 6}), 0);
    EXPECT_EQ(receiver.onFrame(incoming({0x21, 7, 8, 9}), 1).rejected, LinkError::ShortFrame);
    EXPECT_TRUE(receiver.onFrame(incoming({0x21, 7, 8, 9, 10}), 1).completed);
}

TEST_F(IsoTpReceiverTest, NoConsecutiveFrameWithinNCr)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x20, 1, 2, 3, 4, 5, 6}), 2 * kSecond);
    EXPECT_EQ(receiver.nextDeadlineNs(), 3 * kSecond);
    EXPECT_EQ(receiver.poll(3 * kSecond - 1).aborted, LinkError::Ok);
    EXPECT_EQ(receiver.poll(3 * kSecond).aborted, LinkError::TimeoutCr);
    EXPECT_TRUE(receiver.idle());
    EXPECT_EQ(receiver.nextDeadlineNs(), IsoTpReceiver::kNoDeadline);
}

TEST_F(IsoTpReceiverTest, NCrRestartsWithEveryConsecutiveFrame)
{
    IsoTpConfig c = config();
    c.timeoutCrNs = 100 * kMillisecond;
    IsoTpReceiver receiver = make(c);
    receiver.onFrame(incoming({0x10, 0x20, 1, 2, 3, 4, 5, 6}), 0);
    receiver.onFrame(incoming({0x21, 1, 2, 3, 4, 5, 6, 7}), 90 * kMillisecond);
    EXPECT_EQ(receiver.poll(150 * kMillisecond).aborted, LinkError::Ok);
    EXPECT_EQ(receiver.nextDeadlineNs(), 190 * kMillisecond);
    EXPECT_EQ(receiver.poll(190 * kMillisecond).aborted, LinkError::TimeoutCr);
}

TEST_F(IsoTpReceiverTest, NCrRestartsWithEveryFlowControl)
{
    IsoTpConfig c = config();
    c.blockSize = 1;
    IsoTpReceiver receiver = make(c);
    receiver.onFrame(incoming({0x10, 0x20, 1, 2, 3, 4, 5, 6}), 0);
    const IsoTpStep step = receiver.onFrame(incoming({0x21, 1, 2, 3, 4, 5, 6, 7}), 500 * kMillisecond);
    EXPECT_TRUE(step.transmit);
    EXPECT_EQ(receiver.nextDeadlineNs(), 1500 * kMillisecond);
}

TEST_F(IsoTpReceiverTest, LateConsecutiveFrameIsATimeoutEvenWithoutPoll)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x0A, 1, 2, 3, 4, 5, 6}), 0);
    const IsoTpStep late = receiver.onFrame(incoming({0x21, 7, 8, 9, 10}), kSecond);
    EXPECT_EQ(late.aborted, LinkError::TimeoutCr);
    EXPECT_EQ(late.rejected, LinkError::NotExpected);
    EXPECT_FALSE(late.completed);
}

TEST_F(IsoTpReceiverTest, NewSingleFrameDuringAReception)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x20, 1, 2, 3, 4, 5, 6}), 0);
    const IsoTpStep step = receiver.onFrame(incoming({0x02, 0x55, 0x66}), 1);
    EXPECT_EQ(step.aborted, LinkError::UnexpectedPdu);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(received(step), (Bytes{0x55, 0x66}));
    EXPECT_TRUE(receiver.idle());
}

TEST_F(IsoTpReceiverTest, NewFirstFrameDuringAReception)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x20, 1, 2, 3, 4, 5, 6}), 0);
    receiver.onFrame(incoming({0x21, 1, 2, 3, 4, 5, 6, 7}), 1);
    const IsoTpStep step = receiver.onFrame(incoming({0x10, 0x0A, 9, 9, 9, 9, 9, 9}), 2);
    EXPECT_EQ(step.aborted, LinkError::UnexpectedPdu);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(step.frame.byte(0), 0x30);
    // The new message starts at sequence number 1 again.
    const IsoTpStep last = receiver.onFrame(incoming({0x21, 8, 8, 8, 8}), 3);
    EXPECT_TRUE(last.completed);
    EXPECT_EQ(received(last), (Bytes{9, 9, 9, 9, 9, 9, 8, 8, 8, 8}));
}

TEST_F(IsoTpReceiverTest, NewFirstFrameTooLongDuringAReception)
{
    IsoTpReceiver receiver = make(config(), 50);
    receiver.onFrame(incoming({0x10, 0x20, 1, 2, 3, 4, 5, 6}), 0);
    const IsoTpStep step = receiver.onFrame(incoming({0x10, 0x40, 1, 2, 3, 4, 5, 6}), 1);
    EXPECT_EQ(step.aborted, LinkError::UnexpectedPdu);
    EXPECT_EQ(step.rejected, LinkError::BufferOverflow);
    EXPECT_EQ(step.frame.byte(0), 0x32);
    EXPECT_TRUE(receiver.idle());
}

TEST_F(IsoTpReceiverTest, IgnoredFramesDoNotDisturbAReception)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x0A, 1, 2, 3, 4, 5, 6}), 0);
    EXPECT_EQ(receiver.onFrame(incoming({0x00, 1}), 1).rejected, LinkError::InvalidSingleFrameLength);
    EXPECT_EQ(receiver.onFrame(incoming({0x10, 0x03, 1, 2, 3, 4, 5, 6}), 1).rejected, LinkError::InvalidFirstFrame);
    EXPECT_EQ(receiver.onFrame(incoming({0x30, 0x00, 0x00}), 1).rejected, LinkError::NotExpected);
    EXPECT_EQ(receiver.onFrame(incoming({0x50, 0x00}), 1).rejected, LinkError::ReservedPciType);
    EXPECT_EQ(receiver.onFrame(incoming({}), 1).rejected, LinkError::ShortFrame);
    EXPECT_EQ(receiver.onFrame(frame(kTxId, {0x21, 7, 8, 9, 10}), 1).rejected, LinkError::WrongIdentifier);
    EXPECT_EQ(receiver.onFrame(frame(kRxId & 0x7FF, {0x21, 7, 8, 9, 10}, IdFormat::Standard), 1).rejected,
              LinkError::WrongIdentifier);
    EXPECT_EQ(receiver.onFrame(CanFrame::makeRemote(kRxId, IdFormat::Extended, 8).value(), 1).rejected,
              LinkError::UnexpectedRemoteFrame);
    EXPECT_EQ(receiver.poll(2).aborted, LinkError::Ok);
    EXPECT_FALSE(receiver.idle());
    const IsoTpStep last = receiver.onFrame(incoming({0x21, 7, 8, 9, 10}), 3);
    EXPECT_TRUE(last.completed);
    EXPECT_EQ(received(last), (Bytes{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
}

TEST_F(IsoTpReceiverTest, PaddedFramesRequired)
{
    IsoTpConfig c = config();
    c.requirePaddedFrames = true;
    IsoTpReceiver receiver = make(c);
    EXPECT_EQ(receiver.onFrame(incoming({0x02, 1, 2}), 0).rejected, LinkError::ShortFrame);
    EXPECT_TRUE(receiver.onFrame(incoming({0x02, 1, 2, 0xCC, 0xCC, 0xCC, 0xCC, 0xCC}), 0).completed);
    receiver.onFrame(incoming({0x10, 0x09, 1, 2, 3, 4, 5, 6}), 1);
    EXPECT_EQ(receiver.onFrame(incoming({0x21, 7, 8, 9}), 2).rejected, LinkError::ShortFrame);
    EXPECT_TRUE(receiver.onFrame(incoming({0x21, 7, 8, 9, 0xCC, 0xCC, 0xCC, 0xCC}), 2).completed);
}

TEST_F(IsoTpReceiverTest, CreationErrors)
{
    EXPECT_EQ(IsoTpReceiver::create(config(), nullptr, 10).error(), LinkError::InvalidArgument);
    EXPECT_EQ(IsoTpReceiver::create(config(), buffer_, 0).error(), LinkError::InvalidArgument);
    IsoTpConfig c = config();
    c.separationTimeNs = 200 * kMillisecond;
    EXPECT_EQ(IsoTpReceiver::create(c, buffer_, 10).error(), LinkError::InvalidConfiguration);

    IsoTpReceiver placeholder;
    EXPECT_EQ(placeholder.onFrame(incoming({0x01, 1}), 0).rejected, LinkError::InvalidConfiguration);
}

TEST_F(IsoTpReceiverTest, LargerBufferIsUsedUpTo4095Bytes)
{
    static uint8_t large[8192];
    auto receiver = IsoTpReceiver::create(config(), large, sizeof(large));
    ASSERT_TRUE(receiver.ok());
    IsoTpReceiver r = receiver.value();
    EXPECT_EQ(bytesOf(r.onFrame(incoming({0x1F, 0xFF, 1, 2, 3, 4, 5, 6}), 0).frame), (Bytes{0x30, 0x00, 0x00}));
}

TEST_F(IsoTpReceiverTest, AbortDropsTheReception)
{
    IsoTpReceiver receiver = make();
    receiver.onFrame(incoming({0x10, 0x0A, 1, 2, 3, 4, 5, 6}), 0);
    receiver.abort();
    EXPECT_TRUE(receiver.idle());
    EXPECT_EQ(receiver.poll(5 * kSecond).aborted, LinkError::Ok);
    EXPECT_EQ(receiver.onFrame(incoming({0x21, 7, 8, 9, 10}), 1).rejected, LinkError::NotExpected);
}

TEST_F(IsoTpReceiverTest, StandardIdentifiers)
{
    IsoTpConfig c;
    c.format = IdFormat::Standard;
    c.txId = 0x7E8;
    c.rxId = 0x7E0;
    IsoTpReceiver receiver = make(c);
    const IsoTpStep step = receiver.onFrame(frame(0x7E0, {0x10, 0x08, 1, 2, 3, 4, 5, 6}, IdFormat::Standard), 0);
    EXPECT_EQ(step.frame.id(), 0x7E8u);
    EXPECT_FALSE(step.frame.isExtended());
    EXPECT_EQ(receiver.onFrame(incoming({0x21, 7, 8}), 0).rejected, LinkError::WrongIdentifier);
}

} // namespace
