// A sender and a receiver joined by a simulated bus: every message length
// class, block size and separation time arrives intact and paced as asked.
#include <can/IsoTpReceiver.hpp>
#include <can/IsoTpSender.hpp>

#include "IsoTpTestSupport.hpp"

#include <gtest/gtest.h>

#include <map>
#include <tuple>

namespace {

using can::CanFrame;
using can::IsoTpConfig;
using can::IsoTpReceiver;
using can::IsoTpSender;
using can::IsoTpStep;
using can::LinkError;
using namespace isotp_test;

// About one 8-byte extended frame at 500 kbit/s.
constexpr uint64_t kFrameTimeNs = 260000;

struct Outcome {
    bool completed = false;
    std::vector<uint8_t> message;
    int consecutiveFrames = 0;
    int flowControls = 0;
    uint64_t smallestGapNs = IsoTpSender::kNoDeadline; // confirmation of a CF -> the next CF, within a block
    uint64_t endNs = 0;
};

// Runs one transfer with the sender on the "config()" end and the receiver
// on the peer's end; frames take kFrameTimeNs on the bus.
Outcome transfer(const std::vector<uint8_t>& message, uint8_t blockSize, uint32_t separationNs)
{
    IsoTpConfig receiverConfig = peerConfig();
    receiverConfig.blockSize = blockSize;
    receiverConfig.separationTimeNs = separationNs;
    static uint8_t buffer[4095];
    IsoTpReceiver receiver = IsoTpReceiver::create(receiverConfig, buffer, sizeof(buffer)).value();
    IsoTpSender sender = IsoTpSender::create(config()).value();

    enum class Event { DeliverToReceiver, DeliverToSender, ConfirmToSender };
    std::multimap<uint64_t, std::tuple<Event, CanFrame>> events;
    Outcome outcome;
    uint64_t lastCfConfirmation = 0;
    bool cfConfirmedInBlock = false;

    auto sent = [&](const IsoTpStep& step, uint64_t now) {
        EXPECT_EQ(step.aborted, LinkError::Ok);
        if (!step.transmit) {
            return;
        }
        if ((step.frame.byte(0) >> 4) == 2) {
            ++outcome.consecutiveFrames;
            if (cfConfirmedInBlock && now - lastCfConfirmation < outcome.smallestGapNs) {
                outcome.smallestGapNs = now - lastCfConfirmation;
            }
        }
        events.emplace(now + kFrameTimeNs, std::make_tuple(Event::DeliverToReceiver, step.frame));
        events.emplace(now + kFrameTimeNs, std::make_tuple(Event::ConfirmToSender, step.frame));
    };

    sent(sender.start(message.data(), message.size(), 0), 0);
    bool senderDone = false;
    for (int guard = 0; guard < 100000 && !(senderDone && outcome.completed); ++guard) {
        const uint64_t nextEvent = events.empty() ? IsoTpSender::kNoDeadline : events.begin()->first;
        const uint64_t nextPoll = sender.nextDeadlineNs();
        if (nextPoll < nextEvent) {
            sent(sender.poll(nextPoll), nextPoll);
            continue;
        }
        if (events.empty()) {
            break;
        }
        const auto [now, event] = *events.begin();
        events.erase(events.begin());
        const auto& [kind, frame] = event;
        switch (kind) {
        case Event::DeliverToReceiver: {
            const IsoTpStep step = receiver.onFrame(frame, now);
            EXPECT_EQ(step.rejected, LinkError::Ok);
            EXPECT_EQ(step.aborted, LinkError::Ok);
            if (step.transmit) {
                ++outcome.flowControls;
                events.emplace(now + kFrameTimeNs, std::make_tuple(Event::DeliverToSender, step.frame));
            }
            if (step.completed) {
                outcome.completed = true;
                outcome.message.assign(buffer, buffer + step.length);
                outcome.endNs = now;
            }
            break;
        }
        case Event::DeliverToSender:
            // The first consecutive frame after a flow control is not held back by STmin.
            cfConfirmedInBlock = false;
            sent(sender.onFrame(frame, now), now);
            break;
        case Event::ConfirmToSender: {
            const bool consecutive = (frame.byte(0) >> 4) == 2;
            const IsoTpStep step = sender.onTransmitConfirmed(now);
            if (consecutive) {
                lastCfConfirmation = now;
                cfConfirmedInBlock = true;
            }
            senderDone = senderDone || step.completed;
            sent(step, now);
            break;
        }
        }
    }
    EXPECT_TRUE(senderDone);
    EXPECT_TRUE(sender.idle());
    EXPECT_TRUE(receiver.idle());
    return outcome;
}

TEST(IsoTpLoopback, EveryLengthClassArrivesIntact)
{
    for (const size_t length : {1, 6, 7, 8, 13, 14, 20, 21, 111, 112, 113, 1000, 4094, 4095}) {
        const std::vector<uint8_t> message = pattern(length);
        const Outcome outcome = transfer(message, 0, 0);
        ASSERT_TRUE(outcome.completed) << length;
        EXPECT_EQ(outcome.message, message) << length;
        // The first frame carries 6 bytes, every consecutive frame up to 7.
        const int expectedCfs = length <= 7 ? 0 : static_cast<int>((length - 6 + 7 - 1) / 7);
        EXPECT_EQ(outcome.consecutiveFrames, expectedCfs) << length;
        EXPECT_EQ(outcome.flowControls, length <= 7 ? 0 : 1) << length;
    }
}

TEST(IsoTpLoopback, BlockSizesAndSeparationTimes)
{
    const std::vector<uint8_t> message = pattern(500); // 71 CFs
    for (const uint8_t blockSize : {uint8_t{1}, uint8_t{2}, uint8_t{8}, uint8_t{15}, uint8_t{16}, uint8_t{255}}) {
        for (const uint32_t separation : {0u, 100000u, 300000u, 900000u, 1000000u, 7000000u}) {
            const Outcome outcome = transfer(message, blockSize, separation);
            ASSERT_TRUE(outcome.completed) << int(blockSize) << " " << separation;
            EXPECT_EQ(outcome.message, message);
            EXPECT_EQ(outcome.consecutiveFrames, 71);
            // One flow control answers the first frame, one more after every full block but the last.
            EXPECT_EQ(outcome.flowControls, 1 + (71 - 1) / blockSize) << int(blockSize);
            if (separation != 0) {
                EXPECT_GE(outcome.smallestGapNs, separation) << int(blockSize) << " " << separation;
            }
        }
    }
}

TEST(IsoTpLoopback, SeparationTimeSetsTheDuration)
{
    const std::vector<uint8_t> message = pattern(6 + 7 * 10); // 10 CFs
    const Outcome fast = transfer(message, 0, 0);
    const Outcome paced = transfer(message, 0, 5000000);
    ASSERT_TRUE(fast.completed && paced.completed);
    // Nine gaps of 5 ms between the ten consecutive frames.
    EXPECT_GE(paced.endNs - fast.endNs, 9 * 5000000u);
    EXPECT_LT(paced.endNs - fast.endNs, 9 * 5000000u + kFrameTimeNs);
}

} // namespace
