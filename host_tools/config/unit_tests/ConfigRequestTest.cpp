// dcos-config's requests and replies (hostconfig/ConfigRequest.hpp): the
// bytes of the signed requests, their MAC computed again here with
// mbedTLS's HMAC over the byte string docs/protocols/config.md writes
// down (so sei::seiMac and the page are proved to agree, by a second
// implementation), the scan's frames against the node's own CAN server,
// which replies a command takes, the scan line and the refusals' words.
#include <hostconfig/CanConfigLink.hpp>
#include <hostconfig/ConfigRequest.hpp>

#include "ConfigTestNodes.hpp"

#include <sei/CanSeiServer.hpp>

#include <gtest/gtest.h>
#include <mbedtls/md.h>

#include <string>
#include <vector>

namespace {

using config_test::keyOf;
using hostconfig::Bytes;
using hostconfig::Challenge;
using sei::SeiCommand;
using sei::SeiMessage;

constexpr uint16_t kNodeId = 0x0203;
constexpr uint32_t kSerial = 0xA1B2C3D4;

Challenge challengeOf(uint8_t first)
{
    Challenge challenge{};
    for (size_t i = 0; i < challenge.size(); ++i) {
        challenge[i] = static_cast<uint8_t>(first * 7 + i * 13);
    }
    return challenge;
}

SeiMessage requestOf(SeiCommand command)
{
    SeiMessage message;
    message.command = command;
    return message;
}

// The page's MAC, written out independently of firmware/sei: the first 16
// bytes of HMAC-SHA-256 under the key over
// "DCOS-SEI-1" | node id (16) | serial number (32) | challenge | the request without its MAC,
// every number little-endian.
Bytes specMac(const hostconfig::ConfigurationKey& key, uint16_t nodeId, uint32_t serial, const Challenge& challenge,
              const Bytes& requestWithoutMac)
{
    const std::string label = "DCOS-SEI-1";
    Bytes message(label.begin(), label.end());
    message.push_back(static_cast<uint8_t>(nodeId));
    message.push_back(static_cast<uint8_t>(nodeId >> 8));
    for (int shift = 0; shift < 32; shift += 8) {
        message.push_back(static_cast<uint8_t>(serial >> shift));
    }
    message.insert(message.end(), challenge.begin(), challenge.end());
    message.insert(message.end(), requestWithoutMac.begin(), requestWithoutMac.end());
    uint8_t digest[32];
    EXPECT_EQ(mbedtls_md_hmac(mbedtls_md_info_from_type(MBEDTLS_MD_SHA256), key.data(), key.size(), message.data(),
                              message.size(), digest),
              0);
    return Bytes(digest, digest + sei::kSeiMacSize);
}

TEST(ConfigRequestTest, SignedRequestsCarryTheMacThePageDefines)
{
    SeiMessage setNode = requestOf(SeiCommand::SetNodeId);
    setNode.nodeId = 0x0107;
    SeiMessage setRate = requestOf(SeiCommand::SetBitRate);
    setRate.bitRate = 250000;
    // The request without its MAC, byte by byte as the page's table lays it out.
    const std::vector<std::pair<SeiMessage, Bytes>> cases = {
        {setNode, {0x10, 0x07, 0x01}},
        {setRate, {0x11, 0x90, 0xD0, 0x03, 0x00}},
        {requestOf(SeiCommand::Restart), {0x12}},
        {requestOf(SeiCommand::GetConfiguration), {0x03}},
    };
    for (uint8_t round = 0; round < 4; ++round) {
        const hostconfig::ConfigurationKey key = keyOf(static_cast<uint8_t>(0x31 + round * 40));
        const Challenge challenge = challengeOf(round);
        for (const auto& [request, covered] : cases) {
            const Bytes bytes = hostconfig::signedRequest(request, key, kNodeId, kSerial, challenge);
            ASSERT_EQ(bytes.size(), covered.size() + sei::kSeiMacSize);
            EXPECT_EQ(Bytes(bytes.begin(), bytes.begin() + static_cast<long>(covered.size())), covered);
            EXPECT_EQ(Bytes(bytes.begin() + static_cast<long>(covered.size()), bytes.end()),
                      specMac(key, kNodeId, kSerial, challenge, covered))
                << "command 0x" << std::hex << static_cast<int>(covered[0]);
        }
    }
}

TEST(ConfigRequestTest, TheMacBindsNodeSerialChallengeAndKey)
{
    const SeiMessage restart = requestOf(SeiCommand::Restart);
    const Bytes base = hostconfig::signedRequest(restart, keyOf(1), kNodeId, kSerial, challengeOf(1));
    EXPECT_NE(base, hostconfig::signedRequest(restart, keyOf(2), kNodeId, kSerial, challengeOf(1)));
    EXPECT_NE(base, hostconfig::signedRequest(restart, keyOf(1), kNodeId + 1, kSerial, challengeOf(1)));
    EXPECT_NE(base, hostconfig::signedRequest(restart, keyOf(1), kNodeId, kSerial + 1, challengeOf(1)));
    EXPECT_NE(base, hostconfig::signedRequest(restart, keyOf(1), kNodeId, kSerial, challengeOf(2)));
}

TEST(ConfigRequestTest, UnsignedRequestsAreThePagesBytes)
{
    SeiMessage probe = requestOf(SeiCommand::ProbeSerial);
    probe.probeBits = 12;
    probe.probeValue = 0x12300000;
    EXPECT_EQ(hostconfig::encodeRequest(probe), (Bytes{0x20, 12, 0x00, 0x00, 0x30, 0x12}));
    SeiMessage select = requestOf(SeiCommand::Select);
    select.serial = 4711;
    EXPECT_EQ(hostconfig::encodeRequest(select), (Bytes{0x21, 0x67, 0x12, 0x00, 0x00}));
    EXPECT_EQ(hostconfig::encodeRequest(requestOf(SeiCommand::Deselect)), Bytes{0x22});
    EXPECT_EQ(hostconfig::encodeRequest(requestOf(SeiCommand::Identify)), Bytes{0x01});
    EXPECT_EQ(hostconfig::encodeRequest(requestOf(SeiCommand::GetConfiguration)), Bytes{0x03});
}

TEST(ConfigRequestTest, ARequestTakesOnlyTheRepliesToItsCommand)
{
    SeiMessage reply;
    const Bytes challengeReply = [] {
        Bytes bytes{0x82, 0x00};
        bytes.resize(2 + sei::kSeiChallengeSize, 0x5A);
        return bytes;
    }();
    EXPECT_TRUE(hostconfig::answers(SeiCommand::Challenge, challengeReply.data(), challengeReply.size(), reply));
    EXPECT_EQ(reply.challenge[0], 0x5A);
    // A scan's answer, or the reply to an earlier request, is passed over.
    const Bytes probeAnswer{0xA0, 0x00};
    EXPECT_FALSE(hostconfig::answers(SeiCommand::Challenge, probeAnswer.data(), probeAnswer.size(), reply));
    EXPECT_FALSE(hostconfig::answers(SeiCommand::Identify, challengeReply.data(), challengeReply.size(), reply));
    // A refusal and the answer to a request the node could not read are taken.
    const Bytes lockedOut{0x90, 0x06, 0x39, 0x00};
    ASSERT_TRUE(hostconfig::answers(SeiCommand::SetNodeId, lockedOut.data(), lockedOut.size(), reply));
    EXPECT_EQ(reply.status, sei::SeiStatus::LockedOut);
    EXPECT_EQ(reply.lockoutSecondsLeft, 57);
    const Bytes unreadable{0xFF, 0x02};
    ASSERT_TRUE(hostconfig::answers(SeiCommand::SetNodeId, unreadable.data(), unreadable.size(), reply));
    EXPECT_EQ(reply.kind, sei::SeiMessageKind::Unreadable);
    // Bytes that are no message at all.
    const Bytes truncated{0x82, 0x00, 0x01};
    EXPECT_FALSE(hostconfig::answers(SeiCommand::Challenge, truncated.data(), truncated.size(), reply));
}

TEST(ConfigRequestTest, TheScanLineIsStable)
{
    hostconfig::NodeIdentity node;
    node.serial = 4711;
    node.nodeId = 3;
    node.canNode = 3;
    node.board = 1;
    node.version = "1.0.0";
    node.flags = sei::kSeiIdentifyHasKey;
    EXPECT_EQ(hostconfig::scanLine(node), "serial 4711  node 3  can-node 3  isa486  version 1.0.0  key yes  queries open");
    node.flags = sei::kSeiIdentifyQueriesClosed;
    node.board = 77;
    node.version = "1.0.0 rc 1";
    EXPECT_EQ(hostconfig::scanLine(node),
              "serial 4711  node 3  can-node 3  board-77  version 1.0.0_rc_1  key no  queries closed");
}

TEST(ConfigRequestTest, RefusalsAreSaidPlainly)
{
    EXPECT_EQ(hostconfig::refusalText("node 3", sei::SeiStatus::LockedOut, 57),
              "node 3 is locked out for 57 s after three wrong keys");
    EXPECT_EQ(hostconfig::refusalText("node 3", sei::SeiStatus::NoKey, 0),
              "node 3 holds no configuration key: it was made without dcos-card create --config-key");
    EXPECT_EQ(hostconfig::refusalText("node 3", sei::SeiStatus::BadMac, 0).rfind("node 3 refused the key", 0), 0u);
    for (uint8_t status = 1; status <= static_cast<uint8_t>(sei::kSeiLastStatus); ++status) {
        const std::string text = hostconfig::refusalText("node 9", static_cast<sei::SeiStatus>(status), 1);
        EXPECT_EQ(text.rfind("node 9", 0), 0u) << text;
        EXPECT_EQ(text.find("unknown status"), std::string::npos) << text;
    }
}

// The scan's frames against the node's own CAN service: a probe built here
// is taken by a node whose serial number it matches, and its answer is
// what the link recognises; a Deselect ends a selection.
TEST(ConfigRequestTest, ProbeFramesAreTheOnesTheNodesCanServerAnswers)
{
    constexpr uint8_t kHost = sei::kCanSeiHostNode;
    constexpr uint8_t kPriority = sei::kCanSeiPriority;
    const can::IsoTpConfig broadcast = sei::canSeiConnection(255, kHost, kPriority, true);
    EXPECT_EQ(broadcast.txId, 0x1F40FFFEu); // (31, Configuration, 255, 254)
    EXPECT_EQ(broadcast.rxId, 0x1F40FEFFu); // (31, Configuration, 254, 255)
    config_test::MemoryNode node(0x12345678, 1, keyOf(1));
    sei::CanSeiServer server(node.server, 1);

    const auto probeFrame = [&](uint8_t bits, uint32_t value) {
        SeiMessage probe = requestOf(SeiCommand::ProbeSerial);
        probe.probeBits = bits;
        probe.probeValue = value;
        const Bytes bytes = hostconfig::encodeRequest(probe);
        return hostconfig::broadcastFrame(broadcast, bytes.data(), static_cast<uint8_t>(bytes.size()));
    };
    const can::CanFrame matching = probeFrame(16, 0x12340000);
    EXPECT_TRUE(matching.isExtended());
    EXPECT_EQ(matching.id(), broadcast.txId);
    EXPECT_EQ(matching.length(), 7);
    EXPECT_EQ(matching.data()[0], 0x06);
    const sei::CanSeiServer::Output answer = server.onFrame(matching, 1000 * config_test::kMs);
    ASSERT_TRUE(answer.transmit);
    EXPECT_TRUE(hostconfig::isProbeAnswer(answer.frame, broadcast));
    EXPECT_EQ(answer.frame.data()[0], 0x02);
    EXPECT_FALSE(server.onFrame(probeFrame(16, 0x12350000), 1001 * config_test::kMs).transmit);
    EXPECT_TRUE(server.onFrame(probeFrame(32, 0x12345678), 1002 * config_test::kMs).transmit);
    // Another host's answer, or another priority's, is not ours.
    EXPECT_FALSE(hostconfig::isProbeAnswer(answer.frame, sei::canSeiConnection(255, 253, kPriority, true)));
    EXPECT_FALSE(hostconfig::isProbeAnswer(answer.frame, sei::canSeiConnection(255, kHost, 30, true)));

    SeiMessage select = requestOf(SeiCommand::Select);
    select.serial = 0x12345678;
    const Bytes selectBytes = hostconfig::encodeRequest(select);
    const sei::CanSeiServer::Output selected = server.onFrame(
        hostconfig::broadcastFrame(broadcast, selectBytes.data(), static_cast<uint8_t>(selectBytes.size())),
        1003 * config_test::kMs);
    EXPECT_TRUE(selected.transmit);
    EXPECT_EQ(selected.frame.id(), broadcast.rxId);
    EXPECT_FALSE(hostconfig::isProbeAnswer(selected.frame, broadcast));
    EXPECT_TRUE(node.server.selected());
    const uint8_t deselect[] = {static_cast<uint8_t>(SeiCommand::Deselect)};
    EXPECT_FALSE(server.onFrame(hostconfig::broadcastFrame(broadcast, deselect, 1), 1004 * config_test::kMs).transmit);
    EXPECT_FALSE(node.server.selected());
}

} // namespace
