// The SJA1000 chip core and controller through the system agent, with a
// register-level fake chip (FakeSja1000) answering the recording port mock
// and FakeAgents for the interrupt and task services: probe, set-up, the
// transmit queue in arbitration order with aborts for urgent frames,
// reception, bad frames, error states, bus-off and the lone-node hold.
#include <sja1000/IsaSja1000Channel.hpp>
#include <sja1000/Sja1000Chip.hpp>

#include <dcos/SystemAgent.hpp>

#include "../../../firmware/dcos/unit_tests/FakeKernelContext.hpp"
#include "../../iobus/unit_tests/FakeAgents.hpp"
#include "FakeSja1000.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

using can::CanFrame;
using can::IdFormat;
using dcos::ObjectId;
using dcos::ObjectType;
using dcos::Result;
using dcos::Status;
using dcos::systemAgent;
using sja1000::Sja1000Controller;
using sja1000_test::FakeSja1000;
using sja1000_test::kBase;
using sja1000_test::kIrq;
namespace reg = sja1000::reg;

const ObjectId kSuperUser(dcos::fake::kDefaultNode, ObjectType::Task, 10);
const ObjectId kListener(dcos::fake::kDefaultNode, ObjectType::Task, 21);

CanFrame extended(uint32_t id, std::vector<uint8_t> data = {})
{
    return CanFrame::makeData(id, IdFormat::Extended, data.data(), static_cast<uint8_t>(data.size())).value();
}

CanFrame standard(uint32_t id, std::vector<uint8_t> data = {})
{
    return CanFrame::makeData(id, IdFormat::Standard, data.data(), static_cast<uint8_t>(data.size())).value();
}

TEST(Sja1000Chip, ProbeOfAnEmptyBusIsNotFound)
{
    port_io_mock::reset();
    sja1000::Sja1000Chip chip(arch_x86::IoWindow::ports(kBase, reg::kWindowSize));
    EXPECT_EQ(chip.probe(), Status::NotFound);
    const auto log = port_io_mock::takeLog();
    ASSERT_EQ(log.size(), 1u) << port_io_mock::describe(log);
    EXPECT_FALSE(log[0].write) << "nothing is written to an empty slot";
}

TEST(Sja1000Chip, ProbeTakesResetAndPeliCanMode)
{
    port_io_mock::reset();
    FakeSja1000 fake;
    fake.mode = 0; // Operating, as after a warm boot.
    sja1000::Sja1000Chip chip(arch_x86::IoWindow::ports(kBase, reg::kWindowSize));
    EXPECT_EQ(chip.probe(), Status::Ok);
    EXPECT_NE(fake.mode & reg::kModeReset, 0);
    EXPECT_NE(fake.clockDivider & reg::kClockDividerPeliCan, 0);
}

TEST(Sja1000Chip, AChipThatDoesNotLeaveResetIsReportedBusy)
{
    port_io_mock::reset();
    FakeSja1000 fake;
    fake.resetModeIgnored = true;
    sja1000::Sja1000Chip chip(arch_x86::IoWindow::ports(kBase, reg::kWindowSize));
    EXPECT_EQ(chip.start(sja1000::BusMode::Normal), Status::Busy);
}

TEST(Sja1000Chip, FramesRoundTripThroughTheBufferLayout)
{
    port_io_mock::reset();
    FakeSja1000 fake;
    fake.mode = 0;
    sja1000::Sja1000Chip chip(arch_x86::IoWindow::ports(kBase, reg::kWindowSize));
    for (const CanFrame& frame : {extended(0x1ABCDEF, {1, 2, 3}), standard(0x7FF, {9, 8, 7, 6, 5, 4, 3, 2}),
                                  standard(0x123), extended(0x1FFFFFFF, {0xAA}),
                                  CanFrame::makeRemote(0x155, IdFormat::Standard, 4).value(),
                                  CanFrame::makeRemote(0x12345, IdFormat::Extended, 8).value()}) {
        chip.writeTransmitBuffer(frame);
        EXPECT_EQ(fake.transmitted(), frame);
        fake.receive(frame);
        const can::LinkResult<CanFrame> received = chip.readReceiveBuffer();
        ASSERT_TRUE(received.ok());
        EXPECT_EQ(received.value(), frame);
    }
    EXPECT_EQ(fake.releases, 6u) << "every message is released";
}

TEST(Sja1000Chip, ExtendedIdentifierBytesFollowTheDataSheet)
{
    port_io_mock::reset();
    FakeSja1000 fake;
    fake.mode = 0;
    sja1000::Sja1000Chip chip(arch_x86::IoWindow::ports(kBase, reg::kWindowSize));
    chip.writeTransmitBuffer(extended(0x1ABCDEF, {0x42}));
    // ID.28-21, ID.20-13, ID.12-5, ID.4-0 in bits 7:3 (DS 6.4.13).
    EXPECT_EQ(fake.transmitBuffer[0], reg::kFrameExtended | 1);
    EXPECT_EQ(fake.transmitBuffer[1], 0x0D);
    EXPECT_EQ(fake.transmitBuffer[2], 0x5E);
    EXPECT_EQ(fake.transmitBuffer[3], 0x6F);
    EXPECT_EQ(fake.transmitBuffer[4], 0x78);
    EXPECT_EQ(fake.transmitBuffer[5], 0x42);
}

class Sja1000ControllerTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        port_io_mock::reset();
        iobus_fake::reset();
        dcos::fake::reset();
        dcos::fake::playSuperUser(kSuperUser);
        fake = std::make_unique<FakeSja1000>();
    }

    void TearDown() override
    {
        dcos::fake::playSuperUser(kSuperUser);
        while (systemAgent.Close(channel.id()) == Status::Ok) {
        }
        if (channel.installed()) {
            EXPECT_EQ(channel.uninstall(), Status::Ok);
        }
        EXPECT_EQ(iobus::isaResources().release("can-test"), 0u) << "uninstall releases the resources";
        EXPECT_TRUE(iobus_fake::installedIsrs().empty()) << "uninstall removes the routine";
    }

    ObjectId open()
    {
        const Result<ObjectId> id = channel.install("can-test", dcos::Visibility::Local, nullptr);
        EXPECT_TRUE(id.ok()) << dcos::statusName(id.status());
        sja1000::Notification notification{kListener, 1u << 0, 1u << 1, 1u << 2};
        EXPECT_EQ(systemAgent.Open(id.value()), Status::Ok);
        EXPECT_EQ(systemAgent.Control(id.value(), Sja1000Controller::kSetNotification, &notification,
                                      sizeof notification),
                  Status::Ok);
        return id.value();
    }

    size_t send(ObjectId id, const std::vector<CanFrame>& frames)
    {
        const Result<size_t> written = systemAgent.Write(id, 0, frames.data(), frames.size() * sizeof(CanFrame));
        EXPECT_TRUE(written.ok()) << dcos::statusName(written.status());
        return written.ok() ? written.value() / sizeof(CanFrame) : 0;
    }

    std::vector<CanFrame> readAll(ObjectId id)
    {
        std::vector<CanFrame> frames(Sja1000Controller::kReceiveQueueLength + 1);
        const Result<size_t> read = systemAgent.Read(id, 0, frames.data(), frames.size() * sizeof(CanFrame));
        EXPECT_TRUE(read.ok());
        frames.resize(read.ok() ? read.value() / sizeof(CanFrame) : 0);
        return frames;
    }

    void interrupt() { ASSERT_TRUE(iobus_fake::raise(kIrq)); }

    // Completes transmissions one by one and returns the frames in bus order.
    std::vector<CanFrame> drainBus(size_t most = 64)
    {
        std::vector<CanFrame> sent;
        while (fake->transmitting() && sent.size() < most) {
            sent.push_back(fake->transmitted());
            fake->completeTransmission();
            interrupt();
        }
        return sent;
    }

    sja1000::BusState state(ObjectId id)
    {
        sja1000::BusState s{};
        EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kGetState, &s, sizeof s), Status::Ok);
        return s;
    }

    sja1000::ChannelStatistics statistics(ObjectId id)
    {
        sja1000::ChannelStatistics s{};
        EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kGetStatistics, &s, sizeof s), Status::Ok);
        return s;
    }

    std::unique_ptr<FakeSja1000> fake;
    sja1000::IsaSja1000Channel channel{"can-test", kBase, kIrq};
};

TEST_F(Sja1000ControllerTest, OpenConfiguresTheChipAndGoesOnTheBus)
{
    const ObjectId id = open();
    EXPECT_EQ(fake->mode & reg::kModeReset, 0) << "operating mode";
    EXPECT_NE(fake->mode & reg::kModeSingleFilter, 0);
    // The default 125 kbit/s: 16 quanta of 500 ns, sampled at 87.5 %.
    const auto timing = sja1000::BitTimingCalculator::decode(fake->btr0, fake->btr1);
    ASSERT_TRUE(timing.ok());
    EXPECT_EQ(timing.value().bitRate, 125'000u);
    EXPECT_EQ(timing.value().samplePointPermille, 875);
    EXPECT_EQ(fake->outputControl, reg::kOutputControlNormalPushPull);
    for (int i = 4; i < 8; ++i) {
        EXPECT_EQ(fake->acceptance[i], 0xFF) << "the default filter takes every frame";
    }
    EXPECT_NE(fake->interruptEnable & reg::kInterruptReceive, 0);
    EXPECT_NE(fake->interruptEnable & reg::kInterruptBusError, 0);
    EXPECT_EQ(state(id).bitRate, 125'000u);
    EXPECT_EQ(state(id).started, 1);
}

TEST_F(Sja1000ControllerTest, ConflictingPortsAreRefusedAndNothingStaysReserved)
{
    iobus::IsaConflict conflict;
    ASSERT_EQ(iobus::isaResources().reserve("other", kBase + 0x10, 4, iobus::kNoIrq, &conflict), Status::Ok);
    EXPECT_EQ(channel.install("can-test", dcos::Visibility::Local, &conflict).status(), Status::AlreadyExists);
    EXPECT_STREQ(conflict.heldBy, "other");
    EXPECT_TRUE(iobus_fake::installedIsrs().empty());
    EXPECT_EQ(iobus::isaResources().release("other"), 1u);
}

TEST_F(Sja1000ControllerTest, FramesAreSentInArbitrationOrderAndSameIdentifiersKeepTheirOrder)
{
    const ObjectId id = open();
    // The first goes straight into the chip; the rest, written together,
    // queue by identifier, and the most urgent of them displaces it.
    EXPECT_EQ(send(id, {extended(0x300, {1})}), 1u);
    EXPECT_EQ(send(id, {extended(0x500, {1}), extended(0x200, {1}), extended(0x500, {2}), extended(0x100),
                        extended(0x200, {2})}),
              5u);
    interrupt(); // TI of the abort.
    const std::vector<CanFrame> sent = drainBus();
    ASSERT_EQ(sent.size(), 6u);
    EXPECT_EQ(sent[0], extended(0x100));
    EXPECT_EQ(sent[1], extended(0x200, {1}));
    EXPECT_EQ(sent[2], extended(0x200, {2}));
    EXPECT_EQ(sent[3], extended(0x300, {1}));
    EXPECT_EQ(sent[4], extended(0x500, {1}));
    EXPECT_EQ(sent[5], extended(0x500, {2}));
    EXPECT_EQ(statistics(id).framesSent, 6u);
    EXPECT_EQ(statistics(id).aborts, 1u);
    EXPECT_EQ(fake->aborts, 1u);
}

TEST_F(Sja1000ControllerTest, AMoreUrgentFrameDisplacesTheOneWaitingInTheChip)
{
    const ObjectId id = open();
    EXPECT_EQ(send(id, {extended(0x400)}), 1u);
    ASSERT_TRUE(fake->transmitting());
    EXPECT_EQ(fake->transmitted(), extended(0x400));
    EXPECT_EQ(send(id, {extended(0x080)}), 1u);
    EXPECT_EQ(fake->aborts, 1u) << "the less urgent frame is taken back";
    interrupt(); // TI of the abort.
    ASSERT_TRUE(fake->transmitting());
    EXPECT_EQ(fake->transmitted(), extended(0x080));
    const std::vector<CanFrame> sent = drainBus();
    ASSERT_EQ(sent.size(), 2u);
    EXPECT_EQ(sent[0], extended(0x080));
    EXPECT_EQ(sent[1], extended(0x400));
    // A frame as urgent as the one in the chip does not displace it.
    EXPECT_EQ(send(id, {extended(0x100, {1})}), 1u);
    EXPECT_EQ(send(id, {extended(0x100, {2})}), 1u);
    EXPECT_EQ(fake->aborts, 1u);
    const std::vector<CanFrame> more = drainBus();
    ASSERT_EQ(more.size(), 2u);
    EXPECT_EQ(more[0], extended(0x100, {1}));
}

TEST_F(Sja1000ControllerTest, AFullQueueTakesWhatFitsAndSaysSo)
{
    const ObjectId id = open();
    std::vector<CanFrame> frames;
    for (uint32_t i = 0; i < Sja1000Controller::kTransmitQueueLength + 4; ++i) {
        frames.push_back(extended(0x1000 + i));
    }
    EXPECT_EQ(send(id, frames), Sja1000Controller::kTransmitQueueLength);
    EXPECT_EQ(state(id).queued, Sja1000Controller::kTransmitQueueLength);
    EXPECT_EQ(drainBus().size(), Sja1000Controller::kTransmitQueueLength);
    EXPECT_EQ(state(id).queued, 0);
}

TEST_F(Sja1000ControllerTest, BadFramesFromATaskAreRefusedWholeAndNothingIsSent)
{
    const ObjectId id = open();
    // A frame whose bytes did not come from the factories: length 9.
    std::vector<CanFrame> frames{extended(0x10), extended(0x20)};
    uint8_t* bytes = reinterpret_cast<uint8_t*>(&frames[1]);
    for (size_t i = 0; i < sizeof(CanFrame); ++i) {
        bytes[i] = 0xFF; // An identifier past 29 bits, a length past 8.
    }
    const Result<size_t> written = systemAgent.Write(id, 0, frames.data(), frames.size() * sizeof(CanFrame));
    EXPECT_EQ(written.status(), Status::InvalidArgument);
    EXPECT_FALSE(fake->transmitting());
    EXPECT_EQ(systemAgent.Write(id, 0, frames.data(), sizeof(CanFrame) - 1).status(), Status::InvalidArgument);
    EXPECT_EQ(systemAgent.Write(id, 2, frames.data(), sizeof(CanFrame)).status(), Status::InvalidArgument);
    EXPECT_EQ(systemAgent.Read(id, 2, frames.data(), sizeof(CanFrame)).status(), Status::InvalidArgument);
    EXPECT_EQ(systemAgent.Read(id, Sja1000Controller::kTimedChannel, frames.data(), sizeof(CanFrame)).status(),
              Status::InvalidArgument)
        << "the timed channel reads whole TimedFrame objects";
}

TEST_F(Sja1000ControllerTest, ReceivedFramesAreQueuedInOrderAndTheListenerIsTold)
{
    const ObjectId id = open();
    fake->receive(extended(0x111, {1}));
    fake->receive(standard(0x222, {2, 2}));
    interrupt();
    EXPECT_EQ(iobus_fake::postedEvents().size(), 1u) << "one receive event per interrupt";
    EXPECT_EQ(iobus_fake::postedEvents()[0].task, kListener);
    EXPECT_EQ(iobus_fake::postedEvents()[0].events, 1u << 0);
    const std::vector<CanFrame> frames = readAll(id);
    ASSERT_EQ(frames.size(), 2u);
    EXPECT_EQ(frames[0], extended(0x111, {1}));
    EXPECT_EQ(frames[1], standard(0x222, {2, 2}));
    EXPECT_TRUE(readAll(id).empty()) << "a Read with nothing waiting returns at once";
    EXPECT_EQ(statistics(id).framesReceived, 2u);
}

TEST_F(Sja1000ControllerTest, TheTimedChannelStampsEachFrameWithItsInterrupt)
{
    const ObjectId id = open();
    iobus_fake::uptimeNs() = 5'000'000;
    fake->receive(extended(0x111, {1}));
    interrupt();
    iobus_fake::uptimeNs() = 7'000'123;
    fake->receive(extended(0x222, {2}));
    fake->receive(extended(0x333, {3}));
    interrupt();
    sja1000::TimedFrame timed[4];
    const Result<size_t> read = systemAgent.Read(id, Sja1000Controller::kTimedChannel, timed, sizeof timed);
    ASSERT_TRUE(read.ok());
    ASSERT_EQ(read.value(), 3 * sizeof(sja1000::TimedFrame));
    EXPECT_EQ(timed[0].frame, extended(0x111, {1}));
    EXPECT_EQ(timed[0].timeNs, 5'000'000u);
    EXPECT_EQ(timed[1].timeNs, 7'000'123u) << "the frames of one interrupt share its time";
    EXPECT_EQ(timed[2].timeNs, 7'000'123u);
    EXPECT_EQ(timed[2].flags, 0u);
}

TEST_F(Sja1000ControllerTest, AFrameWrittenOnTheTimedChannelComesBackAsAnEchoWhenSent)
{
    const ObjectId id = open();
    const CanFrame sync = extended(0x0004FF01, {0, 1, 2, 3, 4, 5, 6, 7});
    const CanFrame plain = extended(0x0A4FF01, {9});
    ASSERT_EQ(systemAgent.Write(id, Sja1000Controller::kTimedChannel, &sync, sizeof sync).value(), sizeof sync);
    ASSERT_EQ(systemAgent.Write(id, Sja1000Controller::kFrameChannel, &plain, sizeof plain).value(), sizeof plain);
    iobus_fake::uptimeNs() = 42'000'000;
    const std::vector<CanFrame> sent = drainBus();
    ASSERT_EQ(sent.size(), 2u);
    EXPECT_EQ(sent[0], sync);
    EXPECT_EQ(statistics(id).framesReceived, 0u) << "an echo is not a received frame";
    // Channel 0 never sees the echo; channel 1 does, once, with the time of
    // the transmit interrupt.
    sja1000::TimedFrame timed[4];
    const Result<size_t> read = systemAgent.Read(id, Sja1000Controller::kTimedChannel, timed, sizeof timed);
    ASSERT_EQ(read.value(), sizeof(sja1000::TimedFrame)) << "only the frame written on the timed channel";
    EXPECT_EQ(timed[0].frame, sync);
    EXPECT_EQ(timed[0].flags, sja1000::TimedFrame::kEcho);
    EXPECT_EQ(timed[0].timeNs, 42'000'000u);

    ASSERT_EQ(systemAgent.Write(id, Sja1000Controller::kTimedChannel, &sync, sizeof sync).value(), sizeof sync);
    fake->receive(extended(0x555, {5}));
    (void)drainBus();
    const std::vector<CanFrame> plainRead = readAll(id);
    ASSERT_EQ(plainRead.size(), 1u) << "channel 0 skips the echo";
    EXPECT_EQ(plainRead[0], extended(0x555, {5}));
}

TEST_F(Sja1000ControllerTest, AnAbortedFrameComesBackOnlyWhenItIsFinallySent)
{
    const ObjectId id = open();
    const CanFrame slow = extended(0x1F00000, {1});
    const CanFrame urgent = extended(0x0000001, {2});
    ASSERT_EQ(systemAgent.Write(id, Sja1000Controller::kTimedChannel, &slow, sizeof slow).value(), sizeof slow);
    ASSERT_TRUE(fake->transmitting());
    ASSERT_EQ(systemAgent.Write(id, Sja1000Controller::kFrameChannel, &urgent, sizeof urgent).value(), sizeof urgent);
    ASSERT_EQ(fake->aborts, 1u);
    interrupt(); // TI of the abort: no echo for a frame that did not go.
    sja1000::TimedFrame none;
    EXPECT_EQ(systemAgent.Read(id, Sja1000Controller::kTimedChannel, &none, sizeof none).value(), 0u);
    const std::vector<CanFrame> sent = drainBus();
    ASSERT_EQ(sent.size(), 2u);
    EXPECT_EQ(sent[0], urgent);
    sja1000::TimedFrame timed[4];
    const Result<size_t> read = systemAgent.Read(id, Sja1000Controller::kTimedChannel, timed, sizeof timed);
    ASSERT_EQ(read.value(), sizeof(sja1000::TimedFrame)) << "the echo once, after its own transmission";
    EXPECT_EQ(timed[0].frame, slow);
}

TEST_F(Sja1000ControllerTest, AFrameWithALengthAboveEightIsDroppedAndCounted)
{
    const ObjectId id = open();
    fake->receiveRaw(0x0C, {0x12, 0x34, 1, 2, 3, 4, 5, 6, 7, 8}); // Standard, DLC 12.
    fake->receive(standard(0x100, {7}));
    interrupt();
    const std::vector<CanFrame> frames = readAll(id);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0], standard(0x100, {7}));
    EXPECT_EQ(statistics(id).malformedFrames, 1u);
    EXPECT_EQ(fake->releases, 2u) << "the bad message is released too";
}

TEST_F(Sja1000ControllerTest, AFullReceiveQueueCountsWhatItLoses)
{
    const ObjectId id = open();
    for (size_t i = 0; i < Sja1000Controller::kReceiveQueueLength + 3; ++i) {
        fake->receive(extended(static_cast<uint32_t>(i)));
        interrupt();
    }
    EXPECT_EQ(statistics(id).receiveQueueOverruns, 3u);
    const std::vector<CanFrame> frames = readAll(id);
    ASSERT_EQ(frames.size(), Sja1000Controller::kReceiveQueueLength);
    EXPECT_EQ(frames.front(), extended(0)) << "the oldest are kept, in order";
    fake->overrun();
    interrupt();
    EXPECT_EQ(statistics(id).chipOverruns, 1u);
    EXPECT_EQ(fake->status & reg::kStatusDataOverrun, 0) << "the overrun is cleared";
}

TEST_F(Sja1000ControllerTest, ALoneNodeStopsRepeatingAndTriesAgainWhenItHearsAnotherNode)
{
    const ObjectId id = open();
    EXPECT_EQ(send(id, {extended(0x42, {1})}), 1u);
    for (unsigned attempt = 0; attempt < Sja1000Controller::kLoneNodeAttempts; ++attempt) {
        ASSERT_TRUE(fake->transmitting()) << attempt;
        fake->acknowledgeError();
        interrupt();
    }
    // The frame was taken back and the queue is held.
    EXPECT_FALSE(fake->transmitting());
    interrupt();
    EXPECT_FALSE(fake->transmitting());
    EXPECT_EQ(state(id).noAcknowledge, 1);
    EXPECT_EQ(state(id).queued, 1) << "nothing is lost";
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::Passive);
    EXPECT_EQ(statistics(id).acknowledgeErrors, Sja1000Controller::kLoneNodeAttempts);
    EXPECT_EQ(statistics(id).loneNodeHolds, 1u);
    // Another node speaks: the frame goes again, and is taken this time.
    fake->receive(extended(0x99));
    interrupt();
    EXPECT_EQ(state(id).noAcknowledge, 0);
    const std::vector<CanFrame> sent = drainBus();
    ASSERT_EQ(sent.size(), 1u);
    EXPECT_EQ(sent[0], extended(0x42, {1}));
    // The owner's log: warning, passive, then the hold (seen in the state
    // it came in) and its release.
    sja1000::StateChanges log{};
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kReadStateChanges, &log, sizeof log), Status::Ok);
    ASSERT_EQ(log.count, 4u);
    EXPECT_EQ(log.changes[0].to, sja1000::ErrorState::Warning);
    EXPECT_EQ(log.changes[1].to, sja1000::ErrorState::Passive);
    EXPECT_EQ(log.changes[2].holdChanged, 1);
    EXPECT_EQ(log.changes[2].noAcknowledge, 1);
    EXPECT_EQ(log.changes[2].from, log.changes[2].to) << "the error state did not change";
    EXPECT_EQ(log.changes[3].holdChanged, 1);
    EXPECT_EQ(log.changes[3].noAcknowledge, 0);
    EXPECT_EQ(log.changes[0].holdChanged, 0);
}

TEST_F(Sja1000ControllerTest, ErrorStatesAreFollowedAndReportedToTheListener)
{
    const ObjectId id = open();
    fake->setCounters(0, 100);
    interrupt();
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::Warning);
    fake->setCounters(0, 130);
    interrupt();
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::Passive);
    fake->setCounters(0, 10);
    interrupt();
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::Active);
    const sja1000::ChannelStatistics s = statistics(id);
    EXPECT_EQ(s.errorWarnings, 1u);
    EXPECT_EQ(s.errorPassives, 1u);
    size_t stateEvents = 0;
    for (const auto& posted : iobus_fake::postedEvents()) {
        stateEvents += posted.events == (1u << 1) ? 1 : 0;
    }
    EXPECT_EQ(stateEvents, 3u);
}

TEST_F(Sja1000ControllerTest, BusOffRestartsAtOnceAndKeepsTheQueue)
{
    const ObjectId id = open();
    EXPECT_EQ(send(id, {extended(0x10), extended(0x20)}), 2u);
    fake->busOff();
    interrupt();
    EXPECT_EQ(statistics(id).busOffs, 1u);
    EXPECT_EQ(statistics(id).restarts, 1u);
    EXPECT_EQ(fake->mode & reg::kModeReset, 0) << "the chip was told to leave reset mode";
    // Recovered (EI with BS clear): the queue goes out, the interrupted frame first.
    fake->setCounters(0, 0);
    fake->status = static_cast<uint8_t>(fake->status & ~reg::kStatusError);
    fake->interrupt = reg::kInterruptErrorWarning;
    interrupt();
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::Active);
    const std::vector<CanFrame> sent = drainBus();
    ASSERT_EQ(sent.size(), 2u);
    EXPECT_EQ(sent[0], extended(0x10));
}

TEST_F(Sja1000ControllerTest, BusOffWaitsForRestartWhenThePolicySaysSo)
{
    const ObjectId id = open();
    uint32_t policy = static_cast<uint32_t>(sja1000::BusOffPolicy::WaitForRestart);
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kSetBusOffPolicy, &policy, sizeof policy), Status::Ok);
    EXPECT_EQ(send(id, {extended(0x10)}), 1u);
    fake->busOff();
    interrupt();
    EXPECT_NE(fake->mode & reg::kModeReset, 0) << "off the bus until told";
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::BusOff);
    EXPECT_EQ(send(id, {extended(0x20)}), 1u);
    EXPECT_FALSE(fake->transmitting()) << "nothing is sent while bus-off";
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kRestart, nullptr, 0), Status::Ok);
    EXPECT_EQ(fake->mode & reg::kModeReset, 0) << "the chip left reset mode: its recovery has begun";
    EXPECT_EQ(fake->txErrors, 127) << "the counters are the chip's: it counts the 128 bus-free signals itself";
    EXPECT_FALSE(fake->transmitting()) << "nothing is sent before the recovery ends";
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::BusOff);
    // The chip counted 128 bus-free signals: BS clear, counters 0, EI.
    fake->setCounters(0, 0);
    fake->status = static_cast<uint8_t>(fake->status & ~(reg::kStatusBusOff | reg::kStatusError));
    fake->interrupt = reg::kInterruptErrorWarning;
    interrupt();
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::Active);
    EXPECT_EQ(statistics(id).recoveries, 1u);
    EXPECT_EQ(drainBus().size(), 2u);
}

TEST_F(Sja1000ControllerTest, TheOwnerReadsEveryStateChangeInOrder)
{
    const ObjectId id = open();
    fake->setCounters(0, 130);
    interrupt();
    fake->busOff();
    interrupt();
    fake->setCounters(0, 0);
    fake->status = static_cast<uint8_t>(fake->status & ~(reg::kStatusBusOff | reg::kStatusError));
    fake->interrupt = reg::kInterruptErrorWarning;
    interrupt();
    sja1000::StateChanges log{};
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kReadStateChanges, &log, sizeof log), Status::Ok);
    ASSERT_EQ(log.count, 3u);
    EXPECT_EQ(log.lost, 0u);
    EXPECT_EQ(log.changes[0].from, sja1000::ErrorState::Active);
    EXPECT_EQ(log.changes[0].to, sja1000::ErrorState::Passive);
    EXPECT_EQ(log.changes[0].transmitErrors, 130);
    EXPECT_EQ(log.changes[1].to, sja1000::ErrorState::BusOff);
    EXPECT_EQ(log.changes[1].transmitErrors, 127);
    EXPECT_EQ(log.changes[2].from, sja1000::ErrorState::BusOff);
    EXPECT_EQ(log.changes[2].to, sja1000::ErrorState::Active);
    const sja1000::ChannelStatistics s = statistics(id);
    EXPECT_EQ(s.recoveries, 1u);
    EXPECT_EQ(s.errorActives, 1u);
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kReadStateChanges, &log, sizeof log), Status::Ok);
    EXPECT_EQ(log.count, 0u) << "reading empties the log";
}

TEST_F(Sja1000ControllerTest, ARestartWithClearedCountersIsReportedAsAReturnToErrorActive)
{
    const ObjectId id = open();
    fake->setCounters(0, 130);
    interrupt();
    uint32_t rate = 500'000;
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kSetBitRate, &rate, sizeof rate), Status::Ok);
    EXPECT_EQ(state(id).errorState, sja1000::ErrorState::Active);
    sja1000::StateChanges log{};
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kReadStateChanges, &log, sizeof log), Status::Ok);
    ASSERT_EQ(log.count, 2u);
    EXPECT_EQ(log.changes[1].from, sja1000::ErrorState::Passive);
    EXPECT_EQ(log.changes[1].to, sja1000::ErrorState::Active);
    EXPECT_EQ(log.changes[1].transmitErrors, 0) << "the counters were cleared";
    EXPECT_EQ(statistics(id).errorActives, 1u);
}

TEST_F(Sja1000ControllerTest, AFullStateLogKeepsTheNewestAndCountsTheLost)
{
    const ObjectId id = open();
    const size_t changes = sja1000::StateChanges::kCapacity + 4;
    for (size_t i = 0; i < changes; ++i) {
        fake->setCounters(0, i % 2 == 0 ? 130 : 10);
        interrupt();
    }
    sja1000::StateChanges log{};
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kReadStateChanges, &log, sizeof log), Status::Ok);
    EXPECT_EQ(log.count, sja1000::StateChanges::kCapacity);
    EXPECT_EQ(log.lost, 4u);
    EXPECT_EQ(statistics(id).stateChangesLost, 4u);
    EXPECT_EQ(log.changes[log.count - 1].to, sja1000::ErrorState::Active) << "the newest change is kept";
}

TEST_F(Sja1000ControllerTest, FramesOfAFormatTheFilterExcludesAreDroppedAndCounted)
{
    const ObjectId id = open();
    sja1000::AcceptanceFilter filter = sja1000::AcceptanceFilter::extended(0x1000000, 0x1000000);
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kSetFilter, &filter, sizeof filter), Status::Ok);
    // The fake takes every frame, as the chip takes a standard frame whose
    // bits fall on the filter's positions.
    fake->receive(standard(0x400, {1}));
    fake->receive(extended(0x1000042, {2}));
    interrupt();
    const std::vector<CanFrame> frames = readAll(id);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0], extended(0x1000042, {2}));
    EXPECT_EQ(statistics(id).badIdentifiers, 1u);
    EXPECT_EQ(statistics(id).framesReceived, 1u);
    sja1000::AcceptanceFilter bad = filter;
    bad.formats = static_cast<sja1000::FrameFormats>(7);
    EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kSetFilter, &bad, sizeof bad), Status::InvalidArgument);
}

TEST_F(Sja1000ControllerTest, ControlChecksItsArguments)
{
    const ObjectId id = open();
    uint32_t rate = 333'333;
    EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kSetBitRate, &rate, sizeof rate), Status::InvalidArgument);
    rate = 500'000;
    EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kSetBitRate, &rate, sizeof rate - 1), Status::InvalidArgument);
    EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kSetBitRate, &rate, sizeof rate), Status::Ok);
    EXPECT_EQ(sja1000::BitTimingCalculator::decode(fake->btr0, fake->btr1).value().bitRate, 500'000u);
    uint32_t mode = 7;
    EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kSetBusMode, &mode, sizeof mode), Status::InvalidArgument);
    mode = static_cast<uint32_t>(sja1000::BusMode::ListenOnly);
    EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kSetBusMode, &mode, sizeof mode), Status::Ok);
    EXPECT_NE(fake->mode & reg::kModeListenOnly, 0);
    EXPECT_EQ(send(id, {extended(0x10)}), 1u);
    EXPECT_FALSE(fake->transmitting()) << "listen-only never sends";
    EXPECT_EQ(systemAgent.Control(id, 99, nullptr, 0), Status::NotSupported);
    EXPECT_EQ(systemAgent.Control(id, Sja1000Controller::kFlushTransmit, nullptr, 0), Status::Ok);
    EXPECT_EQ(state(id).queued, 0);
}

TEST_F(Sja1000ControllerTest, AFilterIsWrittenLeftAlignedAsTheChipComparesIt)
{
    const ObjectId id = open();
    const sja1000::AcceptanceFilter filter = sja1000::AcceptanceFilter::extended(0x1ABCDE00, 0x1FFFFF00);
    ASSERT_EQ(systemAgent.Control(id, Sja1000Controller::kSetFilter, const_cast<sja1000::AcceptanceFilter*>(&filter),
                                  sizeof filter),
              Status::Ok);
    EXPECT_EQ(fake->acceptance[0], 0xD5); // ID.28-21 of 0x1ABCDE00.
    EXPECT_EQ(fake->acceptance[1], 0xE6);
    EXPECT_EQ(fake->acceptance[2], 0xF0);
    EXPECT_EQ(fake->acceptance[4], 0x00) << "compared bits";
    EXPECT_EQ(fake->acceptance[6], 0x07) << "ID.7-5 don't care";
    EXPECT_EQ(fake->acceptance[7], 0xFF) << "ID.4-0 and RTR: don't care";
    EXPECT_EQ(fake->mode & reg::kModeReset, 0) << "back on the bus after the change";
}

TEST_F(Sja1000ControllerTest, TheInterruptLoopIsBounded)
{
    const ObjectId id = open();
    // A chip that reports a bus error every time IR is read.
    for (unsigned i = 0; i < 100; ++i) {
        port_io_mock::queueRead(kBase + reg::kInterrupt, reg::kInterruptBusError);
    }
    interrupt();
    EXPECT_EQ(statistics(id).interruptLoopLimits, 1u);
    EXPECT_EQ(statistics(id).busErrors, Sja1000Controller::kInterruptLoopBound);
}

TEST_F(Sja1000ControllerTest, ArbitrationFollowsTheStandard)
{
    EXPECT_TRUE(Sja1000Controller::winsArbitration(extended(0x100), extended(0x101)));
    // Equal base identifiers: the standard frame (dominant IDE) wins.
    EXPECT_TRUE(Sja1000Controller::winsArbitration(standard(0x123), extended(0x123u << 18)));
    EXPECT_FALSE(Sja1000Controller::winsArbitration(extended(0x123u << 18), standard(0x123)));
    // A data frame wins over a remote frame with the same identifier.
    EXPECT_TRUE(Sja1000Controller::winsArbitration(standard(0x55),
                                                  CanFrame::makeRemote(0x55, IdFormat::Standard, 0).value()));
    // A lower base identifier wins whatever the format.
    EXPECT_TRUE(Sja1000Controller::winsArbitration(extended(0x122u << 18 | 0x3FFFF), standard(0x123)));
    EXPECT_FALSE(Sja1000Controller::winsArbitration(extended(0x100), extended(0x100))) << "a tie wins nothing";
}

} // namespace
