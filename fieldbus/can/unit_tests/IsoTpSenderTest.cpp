// IsoTpSender: the frames it emits, byte for byte, how it follows flow
// control, and every way a transfer ends early.
#include <can/IsoTpSender.hpp>

#include "IsoTpTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using can::CanFrame;
using can::IdFormat;
using can::IsoTpConfig;
using can::IsoTpSender;
using can::IsoTpStep;
using can::LinkError;
using namespace isotp_test;

using Bytes = std::vector<uint8_t>;

IsoTpSender makeSender(const IsoTpConfig& c = config())
{
    auto sender = IsoTpSender::create(c);
    EXPECT_TRUE(sender.ok());
    return sender.value();
}

// Starts a segmented message and brings the sender to the point where it
// waits for the first flow control.
void startSegmented(IsoTpSender& sender, const Bytes& message, uint64_t now = 0)
{
    const IsoTpStep first = sender.start(message.data(), message.size(), now);
    ASSERT_TRUE(first.transmit);
    ASSERT_EQ(first.frame.byte(0) >> 4, 1) << "a first frame";
    const IsoTpStep confirmed = sender.onTransmitConfirmed(now);
    ASSERT_FALSE(confirmed.transmit);
    ASSERT_EQ(confirmed.aborted, LinkError::Ok);
}

TEST(IsoTpSender, SingleFrameIsTheLengthThenTheData)
{
    IsoTpSender sender = makeSender();
    const Bytes message = {0xDE, 0xAD, 0xBE, 0xEF, 0x42};
    const IsoTpStep step = sender.start(message.data(), message.size(), 0);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(step.rejected, LinkError::Ok);
    EXPECT_EQ(step.frame.id(), kTxId);
    EXPECT_TRUE(step.frame.isExtended());
    // Without padding the frame is as long as N_PCI and data, as Linux sends it.
    EXPECT_EQ(bytesOf(step.frame), (Bytes{0x05, 0xDE, 0xAD, 0xBE, 0xEF, 0x42}));
    EXPECT_FALSE(sender.idle());

    const IsoTpStep done = sender.onTransmitConfirmed(10);
    EXPECT_TRUE(done.completed);
    EXPECT_EQ(done.length, 5);
    EXPECT_FALSE(done.transmit);
    EXPECT_TRUE(sender.idle());
}

TEST(IsoTpSender, SevenBytesStillFitASingleFrame)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(7);
    const IsoTpStep step = sender.start(message.data(), message.size(), 0);
    EXPECT_EQ(step.frame.length(), 8);
    EXPECT_EQ(step.frame.byte(0), 0x07);
}

TEST(IsoTpSender, PaddingFillsEightBytes)
{
    IsoTpConfig c = config();
    c.padding.enabled = true;
    IsoTpSender sender = makeSender(c);
    const Bytes message = {1, 2};
    EXPECT_EQ(bytesOf(sender.start(message.data(), message.size(), 0).frame),
              (Bytes{0x02, 1, 2, 0xCC, 0xCC, 0xCC, 0xCC, 0xCC}));

    c.padding.value = 0x00;
    IsoTpSender zeroPadded = makeSender(c);
    const Bytes ten = pattern(10);
    startSegmented(zeroPadded, ten);
    const IsoTpStep cf = zeroPadded.onFrame(incoming({0x30, 0, 0}), 1);
    EXPECT_EQ(bytesOf(cf.frame), (Bytes{0x21, ten[6], ten[7], ten[8], ten[9], 0, 0, 0}));
}

TEST(IsoTpSender, TenBytesAsLinuxIsotpsendSendsThem)
{
    // isotpsend without options: FF with 6 bytes, FC from the peer, one CF of
    // 4 bytes whose frame is 5 bytes long.
    IsoTpSender sender = makeSender();
    const Bytes message = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A};
    const IsoTpStep first = sender.start(message.data(), message.size(), 0);
    EXPECT_EQ(bytesOf(first.frame), (Bytes{0x10, 0x0A, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06}));
    EXPECT_FALSE(sender.onTransmitConfirmed(1).transmit);

    const IsoTpStep cf = sender.onFrame(incoming({0x30, 0x00, 0x00}), 2);
    ASSERT_TRUE(cf.transmit);
    EXPECT_EQ(cf.rejected, LinkError::Ok);
    EXPECT_EQ(bytesOf(cf.frame), (Bytes{0x21, 0x07, 0x08, 0x09, 0x0A}));
    const IsoTpStep done = sender.onTransmitConfirmed(3);
    EXPECT_TRUE(done.completed);
    EXPECT_EQ(done.length, 10);
    EXPECT_TRUE(sender.idle());
}

TEST(IsoTpSender, LongestMessageWrapsTheSequenceNumber)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(4095);
    const IsoTpStep first = sender.start(message.data(), message.size(), 0);
    EXPECT_EQ(first.frame.byte(0), 0x1F);
    EXPECT_EQ(first.frame.byte(1), 0xFF);
    sender.onTransmitConfirmed(0);

    Bytes sent(message.begin(), message.begin() + 6);
    IsoTpStep step = sender.onFrame(incoming({0x30, 0, 0}), 0);
    int frames = 0;
    while (step.transmit) {
        ++frames;
        EXPECT_EQ(step.frame.byte(0), 0x20 | (frames % 16)) << "frame " << frames;
        sent.insert(sent.end(), step.frame.data() + 1, step.frame.data() + step.frame.length());
        step = sender.onTransmitConfirmed(0);
    }
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.length, 4095);
    EXPECT_EQ(frames, 585); // (4095 - 6) / 7 rounded up
    EXPECT_EQ(sent, message);
}

TEST(IsoTpSender, RefusedMessages)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(4096);
    EXPECT_EQ(sender.start(message.data(), 0, 0).rejected, LinkError::InvalidMessageLength);
    EXPECT_EQ(sender.start(message.data(), 4096, 0).rejected, LinkError::InvalidMessageLength);
    EXPECT_EQ(sender.start(nullptr, 5, 0).rejected, LinkError::InvalidArgument);
    EXPECT_TRUE(sender.idle());

    ASSERT_TRUE(sender.start(message.data(), 20, 0).transmit);
    const IsoTpStep busy = sender.start(message.data(), 3, 0);
    EXPECT_EQ(busy.rejected, LinkError::Busy);
    EXPECT_FALSE(busy.transmit);

    IsoTpSender placeholder;
    EXPECT_EQ(placeholder.start(message.data(), 3, 0).rejected, LinkError::InvalidConfiguration);

    IsoTpConfig bad = config();
    bad.rxId = bad.txId;
    EXPECT_EQ(IsoTpSender::create(bad).error(), LinkError::InvalidConfiguration);
}

TEST(IsoTpSender, BlockSizeWaitsForFlowControlAfterEachBlock)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(6 + 7 * 5); // five full CFs
    startSegmented(sender, message);

    IsoTpStep step = sender.onFrame(incoming({0x30, 0x02, 0x00}), 0);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(step.frame.byte(0), 0x21);
    step = sender.onTransmitConfirmed(0);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(step.frame.byte(0), 0x22);
    step = sender.onTransmitConfirmed(0);
    EXPECT_FALSE(step.transmit) << "the block of 2 is done; the sender waits for flow control";
    EXPECT_EQ(sender.nextDeadlineNs(), kSecond);

    // A later flow control's BS and STmin do not change those of the message.
    step = sender.onFrame(incoming({0x30, 0x05, 0x7F}), 10);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(step.frame.byte(0), 0x23);
    step = sender.onTransmitConfirmed(10);
    ASSERT_TRUE(step.transmit) << "STmin stays 0 from the first flow control";
    EXPECT_EQ(step.frame.byte(0), 0x24);
    step = sender.onTransmitConfirmed(10);
    EXPECT_FALSE(step.transmit) << "BS stays 2 from the first flow control";

    step = sender.onFrame(incoming({0x30, 0x02, 0x00}), 20);
    EXPECT_EQ(step.frame.byte(0), 0x25);
    step = sender.onTransmitConfirmed(20);
    EXPECT_TRUE(step.completed) << "the last CF completes the message even inside a block";
}

TEST(IsoTpSender, BlockSizeOfOneAsksForFlowControlAfterEveryFrame)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(30);
    startSegmented(sender, message);
    int flowControls = 0;
    IsoTpStep step;
    for (;;) {
        step = sender.onFrame(incoming({0x30, 0x01, 0x00}), 0);
        ASSERT_TRUE(step.transmit);
        ++flowControls;
        step = sender.onTransmitConfirmed(0);
        if (step.completed) {
            break;
        }
        ASSERT_FALSE(step.transmit);
    }
    EXPECT_EQ(flowControls, 4); // 24 bytes after the FF: 7 + 7 + 7 + 3
}

TEST(IsoTpSender, SeparationTimeInMilliseconds)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(27); // three CFs
    startSegmented(sender, message);

    // The first CF goes out at once after flow control; STmin separates the next ones.
    IsoTpStep step = sender.onFrame(incoming({0x30, 0x00, 0x05}), 100 * kMillisecond);
    ASSERT_TRUE(step.transmit);
    step = sender.onTransmitConfirmed(101 * kMillisecond);
    EXPECT_FALSE(step.transmit);
    EXPECT_EQ(sender.nextDeadlineNs(), 106 * kMillisecond);
    EXPECT_FALSE(sender.poll(106 * kMillisecond - 1).transmit);
    step = sender.poll(106 * kMillisecond);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(step.frame.byte(0), 0x22);
    EXPECT_EQ(sender.nextDeadlineNs(), 106 * kMillisecond + kSecond) << "now N_As runs";
}

TEST(IsoTpSender, SeparationTimeInHundredsOfMicroseconds)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(27);
    startSegmented(sender, message);
    ASSERT_TRUE(sender.onFrame(incoming({0x30, 0x00, 0xF3}), 0).transmit);
    sender.onTransmitConfirmed(1000);
    EXPECT_EQ(sender.nextDeadlineNs(), 1000 + 300000u);
    EXPECT_FALSE(sender.poll(300999).transmit);
    EXPECT_TRUE(sender.poll(301000).transmit);
}

TEST(IsoTpSender, ReservedSeparationTimeMeans127Milliseconds)
{
    for (const uint8_t reserved : {uint8_t{0x80}, uint8_t{0xF0}, uint8_t{0xFA}, uint8_t{0xFF}}) {
        IsoTpSender sender = makeSender();
        const Bytes message = pattern(27);
        startSegmented(sender, message);
        ASSERT_TRUE(sender.onFrame(incoming({0x30, 0x00, reserved}), 0).transmit);
        sender.onTransmitConfirmed(0);
        EXPECT_EQ(sender.nextDeadlineNs(), 127 * kMillisecond) << std::hex << int(reserved);
    }
}

TEST(IsoTpSender, NoConfirmationWithinNAs)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(3);
    sender.start(message.data(), message.size(), 5 * kMillisecond);
    EXPECT_EQ(sender.nextDeadlineNs(), 5 * kMillisecond + kSecond);
    EXPECT_EQ(sender.poll(5 * kMillisecond + kSecond - 1).aborted, LinkError::Ok);
    const IsoTpStep expired = sender.poll(5 * kMillisecond + kSecond);
    EXPECT_EQ(expired.aborted, LinkError::TimeoutA);
    EXPECT_TRUE(sender.idle());
    EXPECT_EQ(sender.nextDeadlineNs(), IsoTpSender::kNoDeadline);
}

TEST(IsoTpSender, LateConfirmationIsATimeoutEvenWithoutPoll)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(30);
    startSegmented(sender, message);
    ASSERT_TRUE(sender.onFrame(incoming({0x30, 0, 0}), 0).transmit);
    const IsoTpStep late = sender.onTransmitConfirmed(kSecond);
    EXPECT_EQ(late.aborted, LinkError::TimeoutA);
    EXPECT_EQ(late.rejected, LinkError::NotExpected);
    EXPECT_FALSE(late.transmit);
    EXPECT_FALSE(late.completed);
}

TEST(IsoTpSender, NoFlowControlWithinNBs)
{
    IsoTpConfig c = config();
    c.timeoutBsNs = 250 * kMillisecond;
    IsoTpSender sender = makeSender(c);
    const Bytes message = pattern(30);
    startSegmented(sender, message, kSecond);
    EXPECT_EQ(sender.poll(kSecond + 250 * kMillisecond - 1).aborted, LinkError::Ok);
    EXPECT_EQ(sender.poll(kSecond + 250 * kMillisecond).aborted, LinkError::TimeoutBs);
    EXPECT_TRUE(sender.idle());
}

TEST(IsoTpSender, NoFlowControlWithinNBsAfterABlock)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(30);
    startSegmented(sender, message);
    ASSERT_TRUE(sender.onFrame(incoming({0x30, 0x01, 0x00}), 0).transmit);
    sender.onTransmitConfirmed(10);
    const IsoTpStep late = sender.onFrame(incoming({0x30, 0x01, 0x00}), 10 + kSecond);
    EXPECT_EQ(late.aborted, LinkError::TimeoutBs);
    EXPECT_EQ(late.rejected, LinkError::NotExpected);
    EXPECT_FALSE(late.transmit);
}

TEST(IsoTpSender, WaitFramesRestartNBs)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(30);
    startSegmented(sender, message);
    IsoTpStep step = sender.onFrame(incoming({0x31, 0x00, 0x00}), 900 * kMillisecond);
    EXPECT_FALSE(step.transmit);
    EXPECT_EQ(step.aborted, LinkError::Ok);
    EXPECT_EQ(step.rejected, LinkError::Ok);
    EXPECT_EQ(sender.poll(1500 * kMillisecond).aborted, LinkError::Ok);
    EXPECT_EQ(sender.nextDeadlineNs(), 1900 * kMillisecond);
    EXPECT_EQ(sender.poll(1900 * kMillisecond).aborted, LinkError::TimeoutBs);
}

TEST(IsoTpSender, WaitFramesThenContinue)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(10);
    startSegmented(sender, message);
    EXPECT_FALSE(sender.onFrame(incoming({0x31, 0x00, 0x00}), 1).transmit);
    EXPECT_FALSE(sender.onFrame(incoming({0x31, 0x00, 0x00}), 2).transmit);
    const IsoTpStep step = sender.onFrame(incoming({0x30, 0x00, 0x00}), 3);
    ASSERT_TRUE(step.transmit);
    EXPECT_EQ(step.frame.byte(0), 0x21);
    EXPECT_TRUE(sender.onTransmitConfirmed(4).completed);
}

TEST(IsoTpSender, TooManyWaitFramesInARow)
{
    IsoTpConfig c = config();
    c.maxWaitFrames = 2;
    IsoTpSender sender = makeSender(c);
    const Bytes message = pattern(40);
    startSegmented(sender, message);
    EXPECT_EQ(sender.onFrame(incoming({0x31, 0, 0}), 1).aborted, LinkError::Ok);
    EXPECT_EQ(sender.onFrame(incoming({0x31, 0, 0}), 2).aborted, LinkError::Ok);
    // A ContinueToSend resets the count: the limit is on waits in a row.
    ASSERT_TRUE(sender.onFrame(incoming({0x30, 0x01, 0}), 3).transmit);
    sender.onTransmitConfirmed(4);
    EXPECT_EQ(sender.onFrame(incoming({0x31, 0, 0}), 5).aborted, LinkError::Ok);
    EXPECT_EQ(sender.onFrame(incoming({0x31, 0, 0}), 6).aborted, LinkError::Ok);
    const IsoTpStep third = sender.onFrame(incoming({0x31, 0, 0}), 7);
    EXPECT_EQ(third.aborted, LinkError::WaitLimitExceeded);
    EXPECT_TRUE(sender.idle());
}

TEST(IsoTpSender, NoWaitFramesAccepted)
{
    IsoTpConfig c = config();
    c.maxWaitFrames = 0;
    IsoTpSender sender = makeSender(c);
    const Bytes message = pattern(40);
    startSegmented(sender, message);
    EXPECT_EQ(sender.onFrame(incoming({0x31, 0, 0}), 1).aborted, LinkError::WaitLimitExceeded);
}

TEST(IsoTpSender, OverflowAnswersTheFirstFrame)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(4000);
    startSegmented(sender, message);
    const IsoTpStep step = sender.onFrame(incoming({0x32, 0x00, 0x00}), 1);
    EXPECT_EQ(step.aborted, LinkError::BufferOverflow);
    EXPECT_FALSE(step.transmit);
    EXPECT_TRUE(sender.idle());
}

TEST(IsoTpSender, OverflowAfterWaitStillAnswersTheFirstFrame)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(100);
    startSegmented(sender, message);
    sender.onFrame(incoming({0x31, 0, 0}), 1);
    EXPECT_EQ(sender.onFrame(incoming({0x32, 0, 0}), 2).aborted, LinkError::BufferOverflow);
}

TEST(IsoTpSender, OverflowLaterInAMessageIsAnInvalidFlowStatus)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(100);
    startSegmented(sender, message);
    ASSERT_TRUE(sender.onFrame(incoming({0x30, 0x01, 0x00}), 0).transmit);
    sender.onTransmitConfirmed(0);
    EXPECT_EQ(sender.onFrame(incoming({0x32, 0, 0}), 1).aborted, LinkError::InvalidFlowStatus);
    EXPECT_TRUE(sender.idle());
}

TEST(IsoTpSender, ReservedFlowStatus)
{
    for (uint8_t status = 3; status <= 15; ++status) {
        IsoTpSender sender = makeSender();
        const Bytes message = pattern(20);
        startSegmented(sender, message);
        const IsoTpStep step = sender.onFrame(incoming({static_cast<uint8_t>(0x30 | status), 0, 0}), 1);
        EXPECT_EQ(step.aborted, LinkError::InvalidFlowStatus) << int(status);
        EXPECT_FALSE(step.transmit);
    }
}

TEST(IsoTpSender, FramesThatAreIgnored)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(20);
    startSegmented(sender, message);

    EXPECT_EQ(sender.onFrame(frame(kTxId, {0x30, 0, 0}), 1).rejected, LinkError::WrongIdentifier);
    EXPECT_EQ(sender.onFrame(frame(kRxId & 0x7FF, {0x30, 0, 0}, IdFormat::Standard), 1).rejected,
              LinkError::WrongIdentifier);
    EXPECT_EQ(sender.onFrame(CanFrame::makeRemote(kRxId, IdFormat::Extended, 3).value(), 1).rejected,
              LinkError::UnexpectedRemoteFrame);
    EXPECT_EQ(sender.onFrame(incoming({}), 1).rejected, LinkError::ShortFrame);
    EXPECT_EQ(sender.onFrame(incoming({0x30, 0x00}), 1).rejected, LinkError::ShortFrame);
    EXPECT_EQ(sender.onFrame(incoming({0x40, 0x00, 0x00}), 1).rejected, LinkError::ReservedPciType);
    EXPECT_EQ(sender.onFrame(incoming({0x03, 1, 2, 3}), 1).rejected, LinkError::NotExpected);
    EXPECT_EQ(sender.onFrame(incoming({0x10, 0x0A, 1, 2, 3, 4, 5, 6}), 1).rejected, LinkError::NotExpected);
    EXPECT_EQ(sender.onFrame(incoming({0x21, 1, 2}), 1).rejected, LinkError::NotExpected);

    // None of them moved the sender: the real flow control is still awaited.
    const IsoTpStep step = sender.onFrame(incoming({0x30, 0, 0}), 2);
    EXPECT_TRUE(step.transmit);
    EXPECT_EQ(step.frame.byte(0), 0x21);
}

TEST(IsoTpSender, FlowControlWhenNoneIsAwaitedIsIgnored)
{
    IsoTpSender sender = makeSender();
    EXPECT_EQ(sender.onFrame(incoming({0x30, 0, 0}), 0).rejected, LinkError::NotExpected);

    const Bytes message = pattern(30);
    sender.start(message.data(), message.size(), 0);
    EXPECT_EQ(sender.onFrame(incoming({0x30, 0, 0}), 1).rejected, LinkError::NotExpected)
        << "the first frame is not confirmed yet";
    sender.onTransmitConfirmed(2);
    ASSERT_TRUE(sender.onFrame(incoming({0x30, 0, 0x0A}), 3).transmit);
    sender.onTransmitConfirmed(4);
    EXPECT_EQ(sender.onFrame(incoming({0x30, 0, 0}), 5).rejected, LinkError::NotExpected)
        << "during the separation time";
}

TEST(IsoTpSender, PaddedFlowControlRequired)
{
    IsoTpConfig c = config();
    c.requirePaddedFrames = true;
    IsoTpSender sender = makeSender(c);
    const Bytes message = pattern(20);
    startSegmented(sender, message);
    EXPECT_EQ(sender.onFrame(incoming({0x30, 0, 0}), 1).rejected, LinkError::ShortFrame);
    EXPECT_TRUE(sender.onFrame(incoming({0x30, 0, 0, 0xCC, 0xCC, 0xCC, 0xCC, 0xCC}), 1).transmit);
}

TEST(IsoTpSender, ConfirmationWithNothingSent)
{
    IsoTpSender sender = makeSender();
    EXPECT_EQ(sender.onTransmitConfirmed(0).rejected, LinkError::NotExpected);
    const Bytes message = pattern(20);
    startSegmented(sender, message);
    EXPECT_EQ(sender.onTransmitConfirmed(1).rejected, LinkError::NotExpected) << "awaiting flow control";
}

TEST(IsoTpSender, AbortFreesTheSender)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(20);
    startSegmented(sender, message);
    sender.abort();
    EXPECT_TRUE(sender.idle());
    EXPECT_EQ(sender.nextDeadlineNs(), IsoTpSender::kNoDeadline);
    EXPECT_EQ(sender.poll(10 * kSecond).aborted, LinkError::Ok);
    EXPECT_TRUE(sender.start(message.data(), 3, 0).transmit);
}

TEST(IsoTpSender, StandardIdentifiers)
{
    IsoTpConfig c;
    c.format = IdFormat::Standard;
    c.txId = 0x7E0;
    c.rxId = 0x7E8;
    IsoTpSender sender = makeSender(c);
    const Bytes message = pattern(9);
    const IsoTpStep first = sender.start(message.data(), message.size(), 0);
    EXPECT_EQ(first.frame.id(), 0x7E0u);
    EXPECT_FALSE(first.frame.isExtended());
    sender.onTransmitConfirmed(0);
    EXPECT_TRUE(sender.onFrame(frame(0x7E8, {0x30, 0, 0}, IdFormat::Standard), 0).transmit);
}

TEST(IsoTpSender, DeadlinesSaturateInsteadOfWrapping)
{
    IsoTpSender sender = makeSender();
    const Bytes message = pattern(3);
    const uint64_t nearEnd = IsoTpSender::kNoDeadline - 10;
    sender.start(message.data(), message.size(), nearEnd);
    EXPECT_EQ(sender.nextDeadlineNs(), IsoTpSender::kNoDeadline);
    EXPECT_EQ(sender.poll(nearEnd + 5).aborted, LinkError::Ok);
}

} // namespace
