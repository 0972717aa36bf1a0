// The flash protocol on CAN (CanFlashServer): a whole session between the
// host's ISO-TP state machines and a node's server over a simulated bus,
// and what the server does with frames that are not its own, with a host
// that goes away in mid-message, with lost frames, and with a request
// that arrives while a reply is still being sent.
#include <flash/CanFlashServer.hpp>

#include "FlashTestHost.hpp"

#include <can/IsoTpPci.hpp>
#include <can/IsoTpReceiver.hpp>
#include <can/IsoTpSender.hpp>
#include <can/MessageIdentifier.hpp>

#include <gtest/gtest.h>

#include <deque>
#include <functional>
#include <vector>

namespace {

using namespace flash_test;

constexpr uint8_t kNode = 5;
constexpr uint8_t kHost = flash::kCanHostNode;
constexpr uint64_t kMs = 1000000;

can::CanFrame flashFrame(uint8_t priority, uint8_t destination, uint8_t source, std::vector<uint8_t> data,
                         can::MessageType type = can::MessageType::Flashing)
{
    const uint32_t id = can::MessageIdentifier::make(priority, type, destination, source).value().encode();
    return can::CanFrame::makeData(id, can::IdFormat::Extended, data.data(), static_cast<uint8_t>(data.size())).value();
}

// A bus between one host and the node's server. Frames are delivered one at
// a time, in order, and confirmed to their sender as they are delivered;
// time moves only when nothing is on the bus, to the next deadline.
class CanBus {
public:
    CanBus(flash::CanFlashServer& server, uint8_t priority = flash::kCanFlashPriority)
        : server_(server), config_(flash::canFlashConnection(kNode, kHost, priority, true))
    {
        hostSender_ = can::IsoTpSender::create(config_).value();
        hostReceiver_ = can::IsoTpReceiver::create(config_, buffer_, sizeof buffer_).value();
    }

    /// Sends @p request and returns the reply, or nothing when none came
    /// within @p limitNs of emulated time.
    std::optional<std::vector<uint8_t>> exchange(const std::vector<uint8_t>& request, uint64_t limitNs = 5000 * kMs)
    {
        reply_.reset();
        hostStep(hostSender_.start(request.data(), request.size(), now));
        run(limitNs);
        return reply_;
    }

    /// Delivers frames and moves time until the reply arrived, or for @p limitNs.
    void run(uint64_t limitNs)
    {
        const uint64_t end = now + limitNs;
        for (int steps = 0; steps < 100000 && !reply_.has_value(); ++steps) {
            if (!toNode_.empty()) {
                const can::CanFrame frame = toNode_.front();
                toNode_.pop_front();
                const bool lost = dropToNode && dropToNode(toNodeCount_++, frame);
                if (!lost) {
                    nodeStep(server_.onFrame(frame, now));
                }
                hostStep(hostSender_.onTransmitConfirmed(now));
                continue;
            }
            if (!toHost_.empty()) {
                const can::CanFrame frame = toHost_.front();
                toHost_.pop_front();
                const can::LinkResult<can::PciType> type = can::IsoTpPci::typeOf(frame);
                if (type.ok() && type.value() == can::PciType::FlowControl) {
                    hostStep(hostSender_.onFrame(frame, now));
                } else {
                    const can::IsoTpStep step = hostReceiver_.onFrame(frame, now);
                    if (step.completed) {
                        reply_ = std::vector<uint8_t>(buffer_, buffer_ + step.length);
                    }
                    hostStep(step);
                }
                nodeStep(server_.onTransmitConfirmed(now));
                continue;
            }
            const uint64_t next = std::min({server_.nextDeadlineNs(), hostSender_.nextDeadlineNs(),
                                            hostReceiver_.nextDeadlineNs(), end});
            if (next >= end) {
                now = end;
                return;
            }
            now = std::max(now, next);
            nodeStep(server_.poll(now));
            hostStep(hostSender_.poll(now));
            hostStep(hostReceiver_.poll(now));
        }
    }

    /// Puts @p frame on the bus as if another host or node sent it.
    void inject(const can::CanFrame& frame) { nodeStep(server_.onFrame(frame, now)); }

    FlashHost::Carrier carrier()
    {
        return [this](const std::vector<uint8_t>& request) {
            const std::optional<std::vector<uint8_t>> reply = exchange(request);
            EXPECT_TRUE(reply.has_value()) << "no reply over CAN";
            return reply.value_or(std::vector<uint8_t>{});
        };
    }

    uint64_t now = 0;
    /// Loses the frame the host sent as the @p index-th (0 first) when it returns true.
    std::function<bool(unsigned, const can::CanFrame&)> dropToNode;
    std::vector<can::CanFrame> nodeFrames; ///< Every frame the node sent.

private:
    void nodeStep(const flash::CanFlashServer::Output& output)
    {
        if (output.transmit) {
            nodeFrames.push_back(output.frame);
            toHost_.push_back(output.frame);
        }
    }
    void hostStep(const can::IsoTpStep& step)
    {
        if (step.transmit) {
            toNode_.push_back(step.frame);
        }
    }

    flash::CanFlashServer& server_;
    can::IsoTpConfig config_;
    can::IsoTpSender hostSender_;
    can::IsoTpReceiver hostReceiver_;
    uint8_t buffer_[4095] = {};
    std::deque<can::CanFrame> toNode_;
    std::deque<can::CanFrame> toHost_;
    unsigned toNodeCount_ = 0;
    std::optional<std::vector<uint8_t>> reply_;
};

// The encoded Data request for the first KiB of @p image's payload, with @p tag.
std::vector<uint8_t> firstBlock(const std::vector<uint8_t>& image, uint8_t tag)
{
    const std::vector<uint8_t> bytes(image.begin() + 256, image.begin() + 256 + 1024);
    FlashMessage m;
    m.type = MessageType::Data;
    m.tag = tag;
    m.length = 1024;
    m.crc = boot::crc32(bytes.data(), bytes.size());
    m.bytes = bytes.data();
    return encoded(m);
}

class CanFlashServerTest : public ::testing::Test {
protected:
    CanFlashServerTest()
        : keys{trusted(signingKey(0))},
          session(store, keys, 1, identity(), reinterpret_cast<const uint8_t*>("seed"), 4),
          server(session, kNode), bus(server), host(bus.carrier(), kNode)
    {
    }

    static flash::SessionIdentity identity()
    {
        flash::SessionIdentity id;
        id.node = kNode;
        id.mode = flash::NodeMode::Application;
        return id;
    }

    MemoryCard store;
    image::TrustedKey keys[1];
    flash::FlashSession session;
    flash::CanFlashServer server;
    CanBus bus;
    FlashHost host;
};

TEST_F(CanFlashServerTest, AWholeSessionOverIsoTpLeavesTheImagePendingAndRestartsAfterTheReply)
{
    const FlashMessage who = host.hello();
    EXPECT_EQ(who.node, kNode);
    EXPECT_EQ(who.mode, flash::NodeMode::Application);
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> image = imageOf(5000, {1, 0, 0, 0});
    ASSERT_EQ(host.begin(image).status, FlashStatus::Ok);
    EXPECT_EQ(host.sendAll(image).offset, 5000u);
    ASSERT_EQ(host.simple(MessageType::End).status, FlashStatus::Ok);
    ASSERT_TRUE(store.state().has_value());
    EXPECT_EQ(store.state()->trial, boot::TrialState::Pending);
    flash::RestartTarget target{};
    EXPECT_FALSE(server.restartDue(target));
    EXPECT_EQ(host.simple(MessageType::Restart).status, FlashStatus::Ok);
    EXPECT_TRUE(server.restartDue(target)) << "the reply has gone: now the node restarts";
    EXPECT_EQ(target, flash::RestartTarget::Boot);
    EXPECT_EQ(server.statistics().requests, server.statistics().replies);
    EXPECT_EQ(server.statistics().aborted, 0u);
    EXPECT_EQ(server.statistics().connections, 1u);
    // Every frame the node sent is a Flashing frame to the host at the host's priority.
    for (const can::CanFrame& frame : bus.nodeFrames) {
        const can::MessageIdentifier id = can::MessageIdentifier::fromFrame(frame).value();
        EXPECT_EQ(id.type(), can::MessageType::Flashing);
        EXPECT_EQ(id.destination(), kHost);
        EXPECT_EQ(id.source(), kNode);
        EXPECT_EQ(id.priority(), flash::kCanFlashPriority);
    }
}

TEST_F(CanFlashServerTest, TheNodePacesABlockWithItsBlockSize)
{
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> image = imageOf(2048, {1, 0, 0, 0});
    ASSERT_EQ(host.begin(image).status, FlashStatus::Ok);
    bus.nodeFrames.clear();
    ASSERT_EQ(host.block(image, 0, 0, 1024).status, FlashStatus::Ok);
    // A Data message of 16 + 1024 bytes: a first frame and 148 consecutive
    // frames, so ceil(148 / 16) = 10 flow controls, then the reply.
    unsigned flowControls = 0;
    for (const can::CanFrame& frame : bus.nodeFrames) {
        if (can::IsoTpPci::typeOf(frame).value() == can::PciType::FlowControl) {
            ++flowControls;
            EXPECT_EQ(frame.data()[1], flash::kCanNodeBlockSize);
        }
    }
    EXPECT_EQ(flowControls, 10u);
}

TEST_F(CanFlashServerTest, FramesNotForThisNodesFlashProtocolChangeNothing)
{
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    const flash::CanFlashStatistics before = server.statistics();
    const std::vector<uint8_t> hello = {0x02, 0x01, 0x07};
    bus.inject(flashFrame(31, 6, kHost, hello));                   // another node
    bus.inject(flashFrame(31, can::MessageIdentifier::kBroadcast, kHost, hello)); // everyone: never for flashing
    bus.inject(flashFrame(31, kNode, kHost, hello, can::MessageType::RemoteRequest)); // another protocol
    bus.inject(can::CanFrame::makeData(0x123, can::IdFormat::Standard, hello.data(), 3).value()); // not DCOS
    bus.inject(flashFrame(31, kNode, kHost, {}));                   // no PCI at all
    EXPECT_EQ(server.statistics().ignored, before.ignored + 5);
    EXPECT_EQ(server.statistics().requests, before.requests);
    EXPECT_TRUE(bus.nodeFrames.empty() || !server.busy());
    // The session is still authenticated: a Begin goes through.
    EXPECT_EQ(host.begin(imageOf(600, {1, 0, 0, 0})).status, FlashStatus::Ok);
}

TEST_F(CanFlashServerTest, AHostThatStopsInMidMessageIsForgottenAfterNCr)
{
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> image = imageOf(1024, {1, 0, 0, 0});
    ASSERT_EQ(host.begin(image).status, FlashStatus::Ok);
    // The host's 20th frame and everything after it are lost: the node's
    // receiver waits N_Cr (1 s), aborts, and the host's request gets no reply.
    bus.dropToNode = [](unsigned index, const can::CanFrame&) { return index >= 20; };
    EXPECT_FALSE(bus.exchange(firstBlock(image, 99), 3000 * kMs).has_value());
    EXPECT_FALSE(server.busy());
    EXPECT_GE(server.statistics().aborted, 1u);
    // The host comes back and sends the block again: it is taken whole.
    bus.dropToNode = nullptr;
    EXPECT_EQ(host.block(image, 0, 0, 1024).status, FlashStatus::Ok);
    EXPECT_EQ(host.simple(MessageType::End).status, FlashStatus::Ok);
}

TEST_F(CanFlashServerTest, ALostConsecutiveFrameEndsTheRequestAndTheRetryIsTaken)
{
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> image = imageOf(1024, {1, 0, 0, 0});
    ASSERT_EQ(host.begin(image).status, FlashStatus::Ok);
    bus.dropToNode = [](unsigned index, const can::CanFrame&) { return index == 7; };
    EXPECT_FALSE(bus.exchange(firstBlock(image, 42), 3000 * kMs).has_value()) << "a gap in the sequence: no message";
    bus.dropToNode = nullptr;
    EXPECT_EQ(host.block(image, 0, 0, 1024).status, FlashStatus::Ok) << "nothing was written from the broken one";
}

TEST_F(CanFlashServerTest, ARequestWhileTheReplyIsSentEndsThatReply)
{
    // The reply to Hello is long (a first frame and consecutive frames).
    // Lose the host's flow control for it: the node's sender waits for it,
    // and the host, having given up, asks again.
    FlashMessage m;
    m.type = MessageType::Hello;
    m.tag = 1;
    unsigned sent = 0;
    bus.dropToNode = [&sent](unsigned, const can::CanFrame& frame) {
        return can::IsoTpPci::typeOf(frame).value() == can::PciType::FlowControl && sent++ == 0;
    };
    EXPECT_FALSE(bus.exchange(encoded(m), 200 * kMs).has_value());
    EXPECT_TRUE(server.busy()) << "the node still waits for the flow control (N_Bs is 1 s)";
    bus.dropToNode = nullptr;
    const FlashMessage who = host.hello();
    EXPECT_EQ(who.node, kNode);
    EXPECT_GE(server.statistics().aborted, 1u);
}

TEST_F(CanFlashServerTest, AnotherHostOrPriorityBeginsANewConnection)
{
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    EXPECT_EQ(server.peer(), kHost);
    flash::CanFlashServer& node = server;
    CanBus other(node, 3);
    FlashHost urgent(other.carrier(), kNode);
    EXPECT_EQ(urgent.hello().node, kNode);
    EXPECT_EQ(server.statistics().connections, 2u);
    for (const can::CanFrame& frame : other.nodeFrames) {
        EXPECT_EQ(can::MessageIdentifier::fromFrame(frame).value().priority(), 3);
    }
    // The new Hello drew a new challenge: the first host's session is over.
    EXPECT_EQ(host.begin(imageOf(600, {1, 0, 0, 0})).status, FlashStatus::NotAuthenticated);
}

TEST_F(CanFlashServerTest, RestartIntoRecoveryMarksTheBootStateFirst)
{
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    FlashMessage m;
    m.type = MessageType::Restart;
    m.tag = 77;
    m.target = flash::RestartTarget::Recovery;
    EXPECT_EQ(host.ask(m).status, FlashStatus::Ok);
    ASSERT_TRUE(store.state().has_value());
    EXPECT_TRUE(store.state()->recoveryRequested);
    flash::RestartTarget target{};
    EXPECT_TRUE(server.restartDue(target));
    EXPECT_EQ(target, flash::RestartTarget::Recovery);
}

TEST_F(CanFlashServerTest, RestartIntoRecoveryOnACardThatCannotBeWrittenIsRefused)
{
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    store.failing = true;
    FlashMessage m;
    m.type = MessageType::Restart;
    m.tag = 78;
    m.target = flash::RestartTarget::Recovery;
    EXPECT_EQ(host.ask(m).status, FlashStatus::CardError);
    flash::RestartTarget target{};
    EXPECT_FALSE(server.restartDue(target)) << "a node that could not be told to stay in recovery keeps running";
}

TEST(CanFlashSessionTest, ATrialThatRunsIsNeverWrittenOver)
{
    MemoryCard store;
    image::TrustedKey keys[1] = {trusted(signingKey(0))};
    flash::SessionIdentity identity;
    identity.node = kNode;
    identity.mode = flash::NodeMode::Application;
    identity.runningSlot = 0; // The node runs a trial from slot A; nothing is confirmed.
    flash::FlashSession session(store, keys, 1, identity, reinterpret_cast<const uint8_t*>("x"), 1);
    FlashHost host(session, kNode);
    ASSERT_EQ(host.authenticate(), FlashStatus::Ok);
    const unsigned writes = store.writes;
    EXPECT_EQ(host.begin(imageOf(600, {2, 0, 0, 0})).status, FlashStatus::SlotInUse);
    EXPECT_EQ(store.writes, writes);
}

TEST(CanFlashConnectionTest, TheTwoEndsSwapTheirIdentifiers)
{
    const can::IsoTpConfig node = flash::canFlashConnection(5, 254, 31, false);
    const can::IsoTpConfig host = flash::canFlashConnection(5, 254, 31, true);
    EXPECT_EQ(host.txId, node.rxId);
    EXPECT_EQ(host.rxId, node.txId);
    EXPECT_EQ(host.txId, 0x1F5005FEu) << "priority 31, type 0x50, to node 5, from 254";
    EXPECT_EQ(node.blockSize, flash::kCanNodeBlockSize);
    EXPECT_EQ(host.blockSize, 0);
    EXPECT_EQ(node.validate(), can::LinkError::Ok);
}

} // namespace
