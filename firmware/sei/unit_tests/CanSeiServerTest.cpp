// The configuration protocol on CAN (CanSeiServer): whole exchanges between
// the host's ISO-TP state machines and nodes' servers over a simulated bus,
// the scan of two nodes that share a CAN node number (ProbeSerial's binary
// search, then Select), and what nodes do with frames that are not theirs.
#include <sei/CanSeiServer.hpp>

#include "SeiTestSupport.hpp"

#include <can/IsoTpPci.hpp>
#include <can/IsoTpReceiver.hpp>
#include <can/IsoTpSender.hpp>
#include <can/MessageIdentifier.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <functional>
#include <memory>
#include <vector>

namespace {

using namespace sei_test;

constexpr uint8_t kHost = sei::kCanSeiHostNode;
constexpr uint8_t kPriority = sei::kCanSeiPriority;
constexpr uint8_t kBroadcast = can::MessageIdentifier::kBroadcast;
// (31, Configuration, 254, 255): the answers of a scan and of the selected node.
constexpr uint32_t kFromBroadcastToHost = 0x1F40FEFF;

// A node on the bus: its server and its end of the protocol on CAN.
struct CanNode {
    CanNode(std::optional<Key> key, uint32_t serial, uint16_t nodeId)
        : node(key, serial, 0, false, nodeId), can(node.server, static_cast<uint8_t>(nodeId))
    {
    }

    Node node;
    sei::CanSeiServer can;
    std::vector<can::CanFrame> sent; ///< Every frame the node handed to the bus.
};

// A bus between one host and any number of nodes. Frames go on the bus one
// at a time, in order, reach every other party and are confirmed to their
// sender as they are delivered; time moves only when the bus is idle, to
// the next deadline. Two nodes that hand over the same identifier with the
// same bytes while it waits make one frame, as on a real bus; the same
// identifier with other bytes is a collision, which the bus counts.
class CanBus {
public:
    void attach(CanNode& node) { nodes_.push_back(&node); }

    /// Sends @p request to @p address (a node's number, or 255) and returns
    /// the reply, or nothing when none came within @p limitNs of emulated time.
    std::optional<Bytes> exchange(uint8_t address, const Bytes& request, uint64_t limitNs = 3000 * kMs)
    {
        config_ = sei::canSeiConnection(address, kHost, kPriority, true);
        hostSender_ = can::IsoTpSender::create(config_).value();
        hostReceiver_ = can::IsoTpReceiver::create(config_, buffer_, sizeof buffer_).value();
        reply_.reset();
        hostStep(hostSender_.start(request.data(), request.size(), now));
        run(limitNs);
        return reply_;
    }

    SeiHost::Carrier carrier(uint8_t address)
    {
        return [this, address](const Bytes& request) { return exchange(address, request); };
    }

    /// Puts @p frame on the bus as if another host or node sent it.
    void inject(const can::CanFrame& frame)
    {
        queue_.push_back({frame, {}});
        run(0);
    }

    uint64_t now = 0;
    std::vector<can::CanFrame> delivered; ///< Every frame that went on the bus.
    unsigned collisions = 0;

private:
    static constexpr int kHostSender = -1;

    struct OnBus {
        can::CanFrame frame;
        std::vector<int> senders; ///< Node indexes, kHostSender for the host.
    };

    void run(uint64_t limitNs)
    {
        const uint64_t end = now + limitNs;
        for (int steps = 0; steps < 100000; ++steps) {
            if (!queue_.empty()) {
                deliver();
                continue;
            }
            if (reply_.has_value()) {
                return;
            }
            uint64_t next = std::min({hostSender_.nextDeadlineNs(), hostReceiver_.nextDeadlineNs(), end});
            for (CanNode* node : nodes_) {
                next = std::min(next, node->can.nextDeadlineNs());
            }
            if (next >= end) {
                now = end;
                return;
            }
            now = std::max(now, next);
            for (size_t i = 0; i < nodes_.size(); ++i) {
                nodeStep(i, nodes_[i]->can.poll(now));
            }
            hostStep(hostSender_.poll(now));
            hostStep(hostReceiver_.poll(now));
        }
        ADD_FAILURE() << "the bus never went quiet";
    }

    void deliver()
    {
        const OnBus onBus = queue_.front();
        queue_.pop_front();
        delivered.push_back(onBus.frame);
        const auto sentBy = [&onBus](int who) {
            return std::find(onBus.senders.begin(), onBus.senders.end(), who) != onBus.senders.end();
        };
        for (size_t i = 0; i < nodes_.size(); ++i) {
            if (!sentBy(static_cast<int>(i))) {
                nodeStep(i, nodes_[i]->can.onFrame(onBus.frame, now));
            }
        }
        if (!sentBy(kHostSender) && onBus.frame.id() == config_.rxId) {
            const can::LinkResult<can::PciType> type = can::IsoTpPci::typeOf(onBus.frame);
            if (type.ok() && type.value() == can::PciType::FlowControl) {
                hostStep(hostSender_.onFrame(onBus.frame, now));
            } else {
                const can::IsoTpStep step = hostReceiver_.onFrame(onBus.frame, now);
                if (step.completed) {
                    reply_ = Bytes(buffer_, buffer_ + step.length);
                }
                hostStep(step);
            }
        }
        for (const int who : onBus.senders) {
            if (who == kHostSender) {
                hostStep(hostSender_.onTransmitConfirmed(now));
            } else {
                nodeStep(static_cast<size_t>(who), nodes_[static_cast<size_t>(who)]->can.onTransmitConfirmed(now));
            }
        }
    }

    void nodeStep(size_t index, const sei::CanSeiServer::Output& output)
    {
        if (!output.transmit) {
            return;
        }
        nodes_[index]->sent.push_back(output.frame);
        for (OnBus& waiting : queue_) {
            if (waiting.frame.id() != output.frame.id()) {
                continue;
            }
            const bool same = waiting.frame.length() == output.frame.length() &&
                              std::equal(waiting.frame.data(), waiting.frame.data() + waiting.frame.length(),
                                         output.frame.data());
            if (same) {
                waiting.senders.push_back(static_cast<int>(index));
                return;
            }
            ++collisions;
        }
        queue_.push_back({output.frame, {static_cast<int>(index)}});
    }

    void hostStep(const can::IsoTpStep& step)
    {
        if (step.transmit) {
            queue_.push_back({step.frame, {kHostSender}});
        }
    }

    std::vector<CanNode*> nodes_;
    can::IsoTpConfig config_;
    can::IsoTpSender hostSender_;
    can::IsoTpReceiver hostReceiver_;
    uint8_t buffer_[4095] = {};
    std::deque<OnBus> queue_;
    std::optional<Bytes> reply_;
};

can::CanFrame configurationFrame(uint8_t destination, uint8_t source, const Bytes& data,
                                 can::MessageType type = can::MessageType::Configuration)
{
    const uint32_t id = can::MessageIdentifier::make(kPriority, type, destination, source).value().encode();
    return can::CanFrame::makeData(id, can::IdFormat::Extended, data.data(), static_cast<uint8_t>(data.size())).value();
}

Bytes dataOf(const can::CanFrame& frame) { return Bytes(frame.data(), frame.data() + frame.length()); }

// Every serial number on the bus, by ProbeSerial: from the top bit down,
// the branch with the bit 0 is probed; when no node answers, the nodes
// that matched so far must have a 1 there, and that branch is taken
// without a probe. @p probes counts the probes sent.
std::vector<uint32_t> scanSerials(CanBus& bus, unsigned& probes)
{
    std::vector<uint32_t> found;
    const auto answered = [&](uint8_t bits, uint32_t value) {
        ++probes;
        const std::optional<Bytes> answer = bus.exchange(kBroadcast, encoded(probe(bits, value)), sei::kCanSeiProbeWaitNs);
        if (answer.has_value()) {
            EXPECT_EQ(*answer, (Bytes{0xA0, 0x00}));
        }
        return answer.has_value();
    };
    std::function<void(uint8_t, uint32_t)> walk = [&](uint8_t bits, uint32_t value) {
        if (bits == sei::kSeiSerialBits) {
            found.push_back(value);
            return;
        }
        const uint32_t one = value | (0x80000000u >> bits);
        if (answered(static_cast<uint8_t>(bits + 1), value)) {
            walk(static_cast<uint8_t>(bits + 1), value);
            if (answered(static_cast<uint8_t>(bits + 1), one)) {
                walk(static_cast<uint8_t>(bits + 1), one);
            }
        } else {
            walk(static_cast<uint8_t>(bits + 1), one);
        }
    };
    if (answered(0, 0)) {
        walk(0, 0);
    }
    return found;
}

TEST(CanSeiConnectionTest, TheTwoEndsSwapTheirIdentifiers)
{
    const can::IsoTpConfig node = sei::canSeiConnection(5, 254, 31, false);
    const can::IsoTpConfig host = sei::canSeiConnection(5, 254, 31, true);
    EXPECT_EQ(host.txId, 0x1F4005FEu) << "priority 31, type 0x40, to node 5, from 254";
    EXPECT_EQ(host.rxId, 0x1F40FE05u);
    EXPECT_EQ(node.txId, host.rxId);
    EXPECT_EQ(node.rxId, host.txId);
    EXPECT_EQ(node.blockSize, sei::kCanSeiNodeBlockSize);
    EXPECT_EQ(host.blockSize, 0);
    EXPECT_EQ(node.validate(), can::LinkError::Ok);
    const can::IsoTpConfig selected = sei::canSeiConnection(kBroadcast, 254, 31, true);
    EXPECT_EQ(selected.txId, 0x1F40FFFEu) << "to the broadcast address";
    EXPECT_EQ(selected.rxId, kFromBroadcastToHost) << "answered from source 255";
}

class CanSeiServerTest : public ::testing::Test {
protected:
    CanSeiServerTest() : node(keyOf(0x11), 0x12345678, 5), host(bus.carrier(5), keyOf(0x11), 5, 0x12345678)
    {
        bus.attach(node);
    }

    CanBus bus;
    CanNode node;
    SeiHost host;
};

TEST_F(CanSeiServerTest, WholeExchangesOverIsoTp)
{
    EXPECT_EQ(host.raw({0x01}), (Bytes{0x81, 0x00, 0x05, 0x00, 0x05, 0x01, 0x78, 0x56, 0x34, 0x12, 0x01, 0x01, 0x90,
                                       0xD0, 0x03, 0x00, 0x05, 0x00, 0x05, '0', '.', '1', '.', '0'}));
    EXPECT_EQ(dataOf(node.sent.front()), (Bytes{0x10, 24, 0x81, 0x00, 0x05, 0x00, 0x05, 0x01}))
        << "a first frame of 24 bytes";
    EXPECT_EQ(host.ask(request(SeiCommand::GetConfiguration)).sequence, 7u);

    node.sent.clear();
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::Ok) << "a request of 19 bytes: segmented";
    EXPECT_EQ(node.node.backend.configuration.nodeId, 9);
    const auto flowControl = std::find_if(node.sent.begin(), node.sent.end(), [](const can::CanFrame& frame) {
        return can::IsoTpPci::typeOf(frame).value() == can::PciType::FlowControl;
    });
    ASSERT_NE(flowControl, node.sent.end());
    EXPECT_EQ(dataOf(*flowControl), (Bytes{0x30, sei::kCanSeiNodeBlockSize, 0x00}));

    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    const Bytes restart = host.signedBytes(request(SeiCommand::Restart));
    EXPECT_FALSE(node.can.restartDue());
    EXPECT_EQ(bus.exchange(5, restart), (Bytes{0x92, 0x00}));
    EXPECT_TRUE(node.can.restartDue()) << "the reply has gone: now the node restarts";

    const sei::CanSeiStatistics statistics = node.can.statistics();
    EXPECT_EQ(statistics.own.requests, statistics.own.replies);
    EXPECT_EQ(statistics.own.aborted, 0u);
    EXPECT_EQ(statistics.own.connections, 1u);
    EXPECT_EQ(bus.collisions, 0u);
    for (const can::CanFrame& frame : node.sent) {
        EXPECT_EQ(frame.id(), 0x1F40FE05u) << "every answer is a Configuration frame to the host from node 5";
    }
}

TEST_F(CanSeiServerTest, ANodeNotSelectedTakesNothingButScansFromTheBroadcastAddress)
{
    EXPECT_FALSE(bus.exchange(kBroadcast, {0x01}, 100 * kMs).has_value());
    EXPECT_TRUE(node.sent.empty());
    EXPECT_EQ(node.can.statistics().ignored, 1u);
    EXPECT_EQ(bus.exchange(kBroadcast, encoded(probe(0, 0)), sei::kCanSeiProbeWaitNs), (Bytes{0xA0, 0x00}));
    EXPECT_EQ(node.can.statistics().scans, 1u);
    EXPECT_EQ(node.can.statistics().scanAnswers, 1u);
}

TEST_F(CanSeiServerTest, FramesNotForThisNodesProtocolChangeNothing)
{
    const Bytes identify = {0x01, 0x01};
    bus.inject(configurationFrame(6, kHost, identify));                             // another node
    bus.inject(configurationFrame(5, kHost, identify, can::MessageType::Flashing)); // another protocol
    bus.inject(can::CanFrame::makeData(0x123, can::IdFormat::Standard, identify.data(), 2).value()); // not DCOS
    bus.inject(configurationFrame(5, kHost, {}));                                   // no PCI at all
    EXPECT_TRUE(node.sent.empty());
    EXPECT_EQ(node.can.statistics().own.requests, 0u);
    EXPECT_EQ(node.can.statistics().own.ignored + node.can.statistics().ignored, 4u);
    EXPECT_EQ(host.ask(request(SeiCommand::Identify)).serial, 0x12345678u);
}

TEST_F(CanSeiServerTest, AProbeThatMatchesNoNodeLeavesTheBusSilent)
{
    EXPECT_FALSE(bus.exchange(kBroadcast, encoded(probe(32, 0x12345679)), sei::kCanSeiProbeWaitNs).has_value());
    EXPECT_FALSE(bus.exchange(kBroadcast, encoded(probe(1, 0x80000000)), sei::kCanSeiProbeWaitNs).has_value());
    EXPECT_TRUE(node.sent.empty());
    EXPECT_EQ(bus.delivered.size(), 2u) << "only the host's two probes";
    EXPECT_EQ(bus.now, 2 * sei::kCanSeiProbeWaitNs);
}

TEST(CanSeiConfirmationTest, ConfirmationsGoToTheConnectionThatSentFirst)
{
    // A selected node replying on both its connections at once: each
    // confirmation belongs to the older unconfirmed frame of a reply; a
    // scan's answer and flow controls wait for none.
    Node node(keyOf(0x11), 0x12345678, 0, false, 5);
    sei::CanSeiServer server(node.server, 5);
    const auto sf = [](uint8_t destination, uint8_t source, Bytes payload) {
        payload.insert(payload.begin(), static_cast<uint8_t>(payload.size()));
        return configurationFrame(destination, source, payload);
    };
    uint64_t now = 0;
    const sei::CanSeiServer::Output own = server.onFrame(sf(5, kHost, {0x01}), now);
    ASSERT_TRUE(own.transmit);
    EXPECT_EQ(own.frame.id(), 0x1F40FE05u);
    EXPECT_EQ(dataOf(own.frame)[0], 0x10) << "the first frame of Identify's reply";
    const sei::CanSeiServer::Output selected = server.onFrame(sf(kBroadcast, 253, {0x21, 0x78, 0x56, 0x34, 0x12}), now);
    ASSERT_TRUE(selected.transmit);
    EXPECT_EQ(dataOf(selected.frame), (Bytes{0x05, 0xA1, 0x00, 0x05, 0x00, 0x05}));
    const sei::CanSeiServer::Output broadcast = server.onFrame(sf(kBroadcast, 253, {0x01}), now);
    ASSERT_TRUE(broadcast.transmit);
    EXPECT_EQ(broadcast.frame.id(), 0x1F40FDFFu) << "to host 253, from 255";

    // The own reply's first frame went first: its confirmation makes that
    // connection wait for its flow control; the next, the other's.
    EXPECT_FALSE(server.onTransmitConfirmed(now).transmit);
    EXPECT_FALSE(server.onTransmitConfirmed(now).transmit);
    EXPECT_FALSE(server.onTransmitConfirmed(now).transmit) << "the scan's answer waits for nothing";
    const sei::CanSeiServer::Output next = server.onFrame(configurationFrame(kBroadcast, 253, {0x30, 0x00, 0x00}), now);
    ASSERT_TRUE(next.transmit);
    EXPECT_EQ(next.frame.id(), 0x1F40FDFFu);
    EXPECT_EQ(dataOf(next.frame)[0], 0x21) << "the broadcast reply's first consecutive frame";
    const sei::CanSeiServer::Output ownNext = server.onFrame(configurationFrame(5, kHost, {0x30, 0x00, 0x00}), now);
    ASSERT_TRUE(ownNext.transmit);
    EXPECT_EQ(ownNext.frame.id(), 0x1F40FE05u);
    // Both wait now; the broadcast one's frame went out first.
    const sei::CanSeiServer::Output after = server.onTransmitConfirmed(now);
    ASSERT_TRUE(after.transmit);
    EXPECT_EQ(after.frame.id(), 0x1F40FDFFu);
    EXPECT_EQ(dataOf(after.frame)[0], 0x22);
    EXPECT_EQ(server.statistics().scans, 1u);
    EXPECT_EQ(server.statistics().own.connections, 1u);
    EXPECT_EQ(server.statistics().broadcast.connections, 1u);
}

// Two fresh controllers with the same node id, and so the same CAN node
// number: they cannot be told apart by their address, only by their serial
// numbers, which a scan finds.
class CanSeiScanTest : public ::testing::Test {
protected:
    static constexpr uint32_t kSerialA = 0x80000001;
    static constexpr uint32_t kSerialB = 0x80000100;

    CanSeiScanTest() : a(keyOf(0x11), kSerialA, 1), b(keyOf(0x51), kSerialB, 1), silent(keyOf(0x71), 0, 1)
    {
        bus.attach(a);
        bus.attach(b);
        bus.attach(silent);
    }

    CanBus bus;
    CanNode a;
    CanNode b;
    CanNode silent; ///< A node without a serial number takes no part in a scan.
};

TEST_F(CanSeiScanTest, TheNodesAnswerTogetherOnTheirSharedNumber)
{
    // That is why they must be scanned: both answer node 1 at once, with
    // different bytes on the same identifier.
    (void)bus.exchange(1, {0x01}, 100 * kMs);
    EXPECT_GT(bus.collisions, 0u);
}

TEST_F(CanSeiScanTest, ProbeSerialFindsBothSerialNumbersAndSelectConfiguresEachAlone)
{
    unsigned probes = 0;
    std::vector<uint32_t> serials = scanSerials(bus, probes);
    std::sort(serials.begin(), serials.end());
    EXPECT_EQ(serials, (std::vector<uint32_t>{kSerialA, kSerialB}));
    // One probe for any node at all, one for the top bit (both 1: the 0
    // branch is silent), two a bit for the 22 bits they share as 0 and for
    // bit 8 where they part, then A's 8 bits (7 zeros probed both ways, its
    // last 1 inferred) and B's (8 zeros): 1 + 1 + 44 + 2 + 15 + 16.
    EXPECT_EQ(probes, 79u);
    EXPECT_EQ(bus.collisions, 0u) << "every answering node sends the same frame";
    EXPECT_TRUE(silent.sent.empty());
    // The first probe matched both: one frame on the bus, exactly [0xA0][0x00]
    // in an ISO-TP single frame, from source 255.
    ASSERT_GE(bus.delivered.size(), 2u);
    EXPECT_EQ(bus.delivered[1].id(), kFromBroadcastToHost);
    EXPECT_EQ(dataOf(bus.delivered[1]), (Bytes{0x02, 0xA0, 0x00}));
    EXPECT_EQ(a.sent.front().id(), b.sent.front().id());
    EXPECT_EQ(dataOf(a.sent.front()), dataOf(b.sent.front()));

    // Select A: only A answers, from 255, with its node id and CAN node number.
    a.sent.clear();
    b.sent.clear();
    EXPECT_EQ(bus.exchange(kBroadcast, encoded(select(kSerialA)), sei::kCanSeiProbeWaitNs),
              (Bytes{0xA1, 0x00, 0x01, 0x00, 0x01}));
    EXPECT_TRUE(a.node.server.selected());
    EXPECT_FALSE(b.node.server.selected());
    SeiHost toA(bus.carrier(kBroadcast), keyOf(0x11), 1, kSerialA);
    const SeiMessage who = toA.ask(request(SeiCommand::Identify));
    EXPECT_EQ(who.serial, kSerialA);
    EXPECT_EQ(who.flags & sei::kSeiIdentifySelected, sei::kSeiIdentifySelected);
    EXPECT_EQ(toA.authenticated(setNodeId(7)).status, SeiStatus::Ok) << "its own challenge, on 255";
    EXPECT_EQ(a.node.backend.configuration.nodeId, 7);
    EXPECT_EQ(b.node.backend.configuration.nodeId, 1);
    EXPECT_TRUE(b.sent.empty());
    for (const can::CanFrame& frame : a.sent) {
        EXPECT_EQ(frame.id(), kFromBroadcastToHost) << "the selected node answers from 255";
    }

    // Select B: A is deselected, B answers and is configured alone.
    EXPECT_EQ(bus.exchange(kBroadcast, encoded(select(kSerialB)), sei::kCanSeiProbeWaitNs),
              (Bytes{0xA1, 0x00, 0x01, 0x00, 0x01}));
    EXPECT_FALSE(a.node.server.selected());
    EXPECT_TRUE(b.node.server.selected());
    SeiHost toB(bus.carrier(kBroadcast), keyOf(0x51), 1, kSerialB);
    EXPECT_EQ(toB.authenticated(setNodeId(8)).status, SeiStatus::Ok);
    EXPECT_EQ(b.node.backend.configuration.nodeId, 8);
    EXPECT_EQ(a.node.backend.configuration.nodeId, 7);

    // Deselect: no node answers it, and none takes requests on 255 after it.
    EXPECT_FALSE(bus.exchange(kBroadcast, {0x22}, sei::kCanSeiProbeWaitNs).has_value());
    EXPECT_FALSE(b.node.server.selected());
    a.sent.clear();
    b.sent.clear();
    EXPECT_FALSE(bus.exchange(kBroadcast, {0x01}, 100 * kMs).has_value());
    EXPECT_TRUE(a.sent.empty());
    EXPECT_TRUE(b.sent.empty());
    EXPECT_EQ(bus.collisions, 0u);
}

TEST_F(CanSeiScanTest, TheSelectedNodeRestartsAfterItsReplyOnTheBroadcastAddress)
{
    EXPECT_TRUE(bus.exchange(kBroadcast, encoded(select(kSerialB)), sei::kCanSeiProbeWaitNs).has_value());
    SeiHost toB(bus.carrier(kBroadcast), keyOf(0x51), 1, kSerialB);
    EXPECT_EQ(toB.authenticated(request(SeiCommand::Restart)).status, SeiStatus::Ok);
    EXPECT_TRUE(b.can.restartDue());
    EXPECT_FALSE(a.can.restartDue());
}

TEST_F(CanSeiScanTest, AWrongKeyThroughTheBroadcastAddressChangesNothing)
{
    EXPECT_TRUE(bus.exchange(kBroadcast, encoded(select(kSerialA)), sei::kCanSeiProbeWaitNs).has_value());
    SeiHost withBsKey(bus.carrier(kBroadcast), keyOf(0x51), 1, kSerialA);
    EXPECT_EQ(withBsKey.authenticated(setNodeId(9)).status, SeiStatus::BadMac);
    EXPECT_EQ(a.node.backend.configuration.nodeId, 1);
    EXPECT_EQ(b.node.backend.configuration.nodeId, 1);
}

} // namespace
