// RtuReceiver: the states of [SL] Figure 14 with exact timings at 19200 baud
// (character 572917 ns, t1.5 859375 ns, t3.5 2005209 ns).
#include <modbus/RtuReceiver.hpp>

#include "ModbusTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using modbus::RtuReceiver;
using State = modbus::RtuReceiver::State;
using namespace modbus_test;

constexpr uint64_t kChar = 572917;
constexpr uint64_t kT15 = 859375;
constexpr uint64_t kT35 = 2005209;
constexpr uint64_t kStart = 10000000;  // a time well after the Initial state ended

class RtuReceiverTest : public ::testing::Test {
protected:
    RtuReceiverTest() : receiver_(timing19200())
    {
        receiver_.poll(kT35);
        EXPECT_EQ(receiver_.state(), State::Idle);
    }

    // Sends @p bytes back to back from @p startNs (the first byte's end);
    // returns when the last one ended.
    uint64_t send(const Bytes& bytes, uint64_t startNs)
    {
        uint64_t now = startNs;
        for (size_t i = 0; i < bytes.size(); ++i) {
            if (i > 0) {
                now += kChar;
            }
            receiver_.onByte(bytes[i], now);
        }
        return now;
    }

    Bytes delivered()
    {
        EXPECT_TRUE(receiver_.frameReady());
        return bytesOf(receiver_.frame(), receiver_.frameLength());
    }

    RtuReceiver receiver_;
    const Bytes request_ = withCrc({0x01, 0x03, 0x00, 0x00, 0x00, 0x0A});
};

TEST(RtuReceiverInitialTest, WaitsForThreePointFiveCharactersOfSilence)
{
    RtuReceiver receiver(timing19200());
    EXPECT_EQ(receiver.state(), State::Initial);
    EXPECT_EQ(receiver.nextDeadlineNs(), kT35);
    receiver.poll(kT35 - 1);
    EXPECT_EQ(receiver.state(), State::Initial);
    // A character in the Initial state is not a frame: it restarts t3.5.
    receiver.onByte(0x55, kT35 - 1);
    EXPECT_EQ(receiver.counters().ignoredCharacters, 1u);
    receiver.poll(2 * kT35 - 2);
    EXPECT_EQ(receiver.state(), State::Initial);
    receiver.poll(2 * kT35 - 1);
    EXPECT_EQ(receiver.state(), State::Idle);
    EXPECT_TRUE(receiver.idle());
    EXPECT_EQ(receiver.nextDeadlineNs(), RtuReceiver::kNoDeadline);
    EXPECT_EQ(receiver.counters().busMessages, 0u);
}

TEST_F(RtuReceiverTest, FrameEndsAfterThreePointFiveCharacters)
{
    const uint64_t last = send(request_, kStart);
    EXPECT_EQ(receiver_.state(), State::Reception);
    EXPECT_EQ(receiver_.nextDeadlineNs(), last + kT35);
    receiver_.poll(last + kT15);
    EXPECT_EQ(receiver_.state(), State::Reception);
    receiver_.poll(last + kT15 + 1);
    EXPECT_EQ(receiver_.state(), State::ControlAndWaiting);
    receiver_.poll(last + kT35 - 1);
    EXPECT_FALSE(receiver_.frameReady());
    receiver_.poll(last + kT35);
    EXPECT_EQ(receiver_.state(), State::Idle);
    EXPECT_EQ(delivered(), request_);
    EXPECT_EQ(receiver_.counters().framesDelivered, 1u);
    EXPECT_EQ(receiver_.counters().busMessages, 1u);
    receiver_.takeFrame();
    EXPECT_FALSE(receiver_.frameReady());
}

TEST_F(RtuReceiverTest, GapOfExactlyOnePointFiveCharactersIsAllowed)
{
    uint64_t now = send(Bytes(request_.begin(), request_.begin() + 3), kStart);
    // The next character ends one character time after its start, which
    // comes t1.5 after the previous character ended.
    now += kT15 + kChar;
    now = send(Bytes(request_.begin() + 3, request_.end()), now);
    receiver_.poll(now + kT35);
    EXPECT_EQ(delivered(), request_);
    EXPECT_EQ(receiver_.counters().gapErrors, 0u);
}

TEST_F(RtuReceiverTest, GapAboveOnePointFiveCharactersMakesTheFrameNotOk)
{
    uint64_t now = send(Bytes(request_.begin(), request_.begin() + 3), kStart);
    now += kT15 + 1 + kChar;
    now = send(Bytes(request_.begin() + 3, request_.end()), now);
    receiver_.poll(now + kT35);
    EXPECT_FALSE(receiver_.frameReady());
    // The whole burst was one frame, discarded.
    EXPECT_EQ(receiver_.counters().gapErrors, 1u);
    EXPECT_EQ(receiver_.counters().busMessages, 1u);
    EXPECT_EQ(receiver_.counters().framesDelivered, 0u);
    EXPECT_EQ(receiver_.state(), State::Idle);
}

// A character the UART flagged (parity, framing, break) makes its frame "not
// OK" even when the CRC happens to match ([SL] Figure 14 controls parity with
// the CRC); the next frame is delivered again.
TEST_F(RtuReceiverTest, AFrameWithADamagedCharacterIsDiscardedWhateverItsCrc)
{
    uint64_t now = send(Bytes(request_.begin(), request_.begin() + 3), kStart);
    receiver_.markLastCharacterDamaged();
    now = send(Bytes(request_.begin() + 3, request_.end()), now + kChar);
    receiver_.poll(now + kT35);
    EXPECT_FALSE(receiver_.frameReady());
    EXPECT_EQ(receiver_.counters().damagedFrames, 1u);
    EXPECT_EQ(receiver_.counters().crcErrors, 0u);
    EXPECT_EQ(receiver_.counters().busMessages, 1u);
    now = send(request_, now + kT35 + kChar);
    receiver_.poll(now + kT35);
    EXPECT_EQ(delivered(), request_);
    EXPECT_EQ(receiver_.counters().damagedFrames, 1u);
}

// A damaged character the receiver ignored (the Initial state) marks nothing.
TEST(RtuReceiverInitialTest, ADamagedCharacterBeforeTheLineWasIdleMarksNothing)
{
    RtuReceiver receiver(timing19200());
    receiver.onByte(0x55, kT35 - 1);
    receiver.markLastCharacterDamaged();
    receiver.poll(2 * kT35 - 1);
    EXPECT_TRUE(receiver.idle());
    const Bytes request = withCrc({0x01, 0x03, 0x00, 0x00, 0x00, 0x0A});
    uint64_t now = 3 * kT35;
    for (uint8_t byte : request) {
        receiver.onByte(byte, now);
        now += kChar;
    }
    receiver.poll(now + kT35);
    EXPECT_TRUE(receiver.frameReady());
    EXPECT_EQ(receiver.counters().damagedFrames, 0u);
}

TEST_F(RtuReceiverTest, CharacterDuringControlAndWaitingWithoutPollIsDetected)
{
    // The same, with a poll that puts the machine in Control and waiting first.
    uint64_t now = send(Bytes(request_.begin(), request_.begin() + 4), kStart);
    receiver_.poll(now + kT35 - 1);
    EXPECT_EQ(receiver_.state(), State::ControlAndWaiting);
    now = send(Bytes(request_.begin() + 4, request_.end()), now + kT35 - 1 + kChar);
    receiver_.poll(now + kT35);
    EXPECT_FALSE(receiver_.frameReady());
    EXPECT_EQ(receiver_.counters().gapErrors, 1u);
}

TEST_F(RtuReceiverTest, SilenceOfThreePointFiveCharactersSeparatesTwoFrames)
{
    const Bytes second = withCrc({0x02, 0x04, 0x00, 0x01, 0x00, 0x02});
    uint64_t now = send(request_, kStart);
    // The next frame's first character starts exactly t3.5 later: it is a new
    // frame, and the first one is delivered on the way.
    now = send(second, now + kT35 + kChar);
    EXPECT_EQ(delivered(), request_);
    receiver_.takeFrame();
    receiver_.poll(now + kT35);
    EXPECT_EQ(delivered(), second);
    EXPECT_EQ(receiver_.counters().framesDelivered, 2u);
    EXPECT_EQ(receiver_.counters().framesLost, 0u);
}

TEST_F(RtuReceiverTest, UntakenFrameIsReplacedAndCountedLost)
{
    const Bytes second = withCrc({0x02, 0x04, 0x00, 0x01, 0x00, 0x02});
    uint64_t now = send(request_, kStart);
    now = send(second, now + kT35 + kChar);
    receiver_.poll(now + kT35);
    EXPECT_EQ(delivered(), second);
    EXPECT_EQ(receiver_.counters().framesLost, 1u);
}

TEST_F(RtuReceiverTest, DeliveredFrameSurvivesTheNextFrameArriving)
{
    uint64_t now = send(request_, kStart);
    receiver_.poll(now + kT35);
    ASSERT_TRUE(receiver_.frameReady());
    send(withCrc({0x09, 0x09, 0x09, 0x09}), now + kT35 + kChar);
    EXPECT_EQ(delivered(), request_);
}

TEST_F(RtuReceiverTest, BadCrcIsDiscardedAndCounted)
{
    Bytes corrupted = request_;
    corrupted[3] ^= 0x01;
    const uint64_t now = send(corrupted, kStart);
    receiver_.poll(now + kT35);
    EXPECT_FALSE(receiver_.frameReady());
    EXPECT_EQ(receiver_.counters().crcErrors, 1u);
    EXPECT_EQ(receiver_.counters().busMessages, 1u);
}

TEST_F(RtuReceiverTest, FramesShorterThanFourBytesAreDiscarded)
{
    // Three bytes whose last two are even the right CRC of the first.
    const Bytes shortFrame = withCrc({0x01});
    const uint64_t now = send(shortFrame, kStart);
    receiver_.poll(now + kT35);
    EXPECT_FALSE(receiver_.frameReady());
    EXPECT_EQ(receiver_.counters().shortFrames, 1u);
}

TEST_F(RtuReceiverTest, LongestFrameIsDeliveredAndOneByteMoreIsAnOverrun)
{
    Bytes longest(254, 0x5A);
    longest[0] = 0x01;
    longest = withCrc(longest);
    ASSERT_EQ(longest.size(), 256u);
    uint64_t now = send(longest, kStart);
    receiver_.poll(now + kT35);
    EXPECT_EQ(delivered(), longest);
    receiver_.takeFrame();

    Bytes overlong(255, 0x5A);
    overlong = withCrc(overlong);
    now = send(overlong, now + 2 * kT35);
    receiver_.poll(now + kT35);
    EXPECT_FALSE(receiver_.frameReady());
    EXPECT_EQ(receiver_.counters().overruns, 1u);
    EXPECT_EQ(receiver_.state(), State::Idle);
}

TEST_F(RtuReceiverTest, FifoBurstWithOneTimestampIsOneFrame)
{
    receiver_.onBytes(request_.data(), request_.size(), kStart);
    receiver_.poll(kStart + kT35);
    EXPECT_EQ(delivered(), request_);
}

TEST_F(RtuReceiverTest, RestartSilenceDropsAPartialFrameAndWaitsThreePointFive)
{
    send(Bytes(request_.begin(), request_.begin() + 3), kStart);
    receiver_.restartSilence(kStart + 5 * kChar);
    EXPECT_EQ(receiver_.state(), State::Initial);
    receiver_.poll(kStart + 5 * kChar + kT35 - 1);
    EXPECT_FALSE(receiver_.idle());
    receiver_.poll(kStart + 5 * kChar + kT35);
    EXPECT_TRUE(receiver_.idle());
    EXPECT_EQ(receiver_.counters().busMessages, 0u);
    // A whole frame afterwards is received normally.
    const uint64_t now = send(request_, kStart + 20 * kChar);
    receiver_.poll(now + kT35);
    EXPECT_EQ(delivered(), request_);
}

TEST_F(RtuReceiverTest, TimeGoingBackwardsNeverExpiresATimer)
{
    const uint64_t now = send(request_, kStart);
    receiver_.poll(now - 5 * kChar);
    EXPECT_EQ(receiver_.state(), State::Reception);
    receiver_.onByte(0xFF, now - kChar);
    receiver_.poll(now + kT35);
    // The late byte is part of the frame, whose CRC is now wrong.
    EXPECT_EQ(receiver_.counters().crcErrors, 1u);
}

} // namespace
