// dcos-config's conversation (hostconfig::ConfigClient) with nodes in
// memory that run the protocol's own server: what the tool does on the
// bus, end to end but for CAN. Identify, the configuration with and
// without the key, the authenticated changes and each refusal the tool
// must put in words (wrong key, lockout, no key, closed queries, a value
// out of range), a lost reply asked again under a new challenge, a Restart
// never sent twice, and a scan of nodes that share a CAN node number,
// configured one by one through the broadcast address.
#include <hostconfig/ConfigClient.hpp>

#include "ConfigTestNodes.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

using config_test::keyOf;
using config_test::MemoryBus;
using config_test::MemoryNode;
using hostconfig::ConfigClient;
using hostconfig::ConfigError;
using hostconfig::NodeConfiguration;
using hostconfig::NodeIdentity;
using sei::SeiCommand;
using sei::SeiStatus;

constexpr hostconfig::ClientOptions kOptions{std::chrono::milliseconds(100), 3};

NodeIdentity identified(ConfigClient& client)
{
    NodeIdentity node;
    const ConfigError error = client.identify(node);
    EXPECT_FALSE(error) << error.why;
    return node;
}

TEST(ConfigClientTest, IdentifiesANodeAtItsNumber)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    EXPECT_EQ(identity.serial, 4711u);
    EXPECT_EQ(identity.nodeId, 3);
    EXPECT_EQ(identity.canNode, 3);
    EXPECT_EQ(identity.board, 1);
    EXPECT_EQ(identity.protocol, sei::kSeiProtocolVersion);
    EXPECT_EQ(identity.version, "1.0.0");
    EXPECT_TRUE(identity.hasKey());
    EXPECT_FALSE(identity.queriesClosed());
    EXPECT_EQ(identity.bitRate, 250000u);
    EXPECT_EQ(hostconfig::scanLine(identity),
              "serial 4711  node 3  can-node 3  isa486  version 1.0.0  key yes  queries open");
}

TEST(ConfigClientTest, ReadsTheConfigurationWithAndWithoutTheKey)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    NodeConfiguration configuration;
    ASSERT_FALSE(client.getConfiguration(identity, nullptr, configuration));
    EXPECT_EQ(configuration.sequence, 7u);
    EXPECT_EQ(configuration.nodeId, 3);
    EXPECT_EQ(configuration.bitRate, 250000u);
    EXPECT_EQ(configuration.commandLine, "can0=250000");
    EXPECT_EQ(bus.sent(SeiCommand::Challenge), 0u);
    // With the key the request carries a MAC, which the node checks.
    const hostconfig::ConfigurationKey key = keyOf(1);
    ASSERT_FALSE(client.getConfiguration(identity, &key, configuration));
    EXPECT_EQ(bus.sent(SeiCommand::Challenge), 1u);
    const hostconfig::ConfigurationKey wrong = keyOf(2);
    const ConfigError refused = client.getConfiguration(identity, &wrong, configuration);
    EXPECT_EQ(refused.kind, ConfigError::Kind::Refused);
    EXPECT_EQ(refused.status, SeiStatus::BadMac);
}

TEST(ConfigClientTest, ClosedQueriesNeedTheKey)
{
    MemoryNode node(4711, 3, keyOf(1), true);
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    EXPECT_TRUE(identity.queriesClosed());
    NodeConfiguration configuration;
    const ConfigError refused = client.getConfiguration(identity, nullptr, configuration);
    EXPECT_EQ(refused.kind, ConfigError::Kind::Refused);
    EXPECT_EQ(refused.status, SeiStatus::NotPermitted);
    const hostconfig::ConfigurationKey key = keyOf(1);
    ASSERT_FALSE(client.getConfiguration(identity, &key, configuration));
    EXPECT_TRUE(configuration.queriesClosed());
}

TEST(ConfigClientTest, ChangesSignedWithTheNodesKeyAreWritten)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    uint32_t sequence = 0;
    ASSERT_FALSE(client.setNodeId(identity, keyOf(1), 9, sequence));
    EXPECT_EQ(sequence, 8u);
    EXPECT_EQ(node.backend.configuration.nodeId, 9);
    ASSERT_FALSE(client.setBitRate(identity, keyOf(1), 500000, sequence));
    EXPECT_EQ(sequence, 9u);
    EXPECT_EQ(node.backend.configuration.bitRate, 500000u);
    ASSERT_FALSE(client.restart(identity, keyOf(1)));
    EXPECT_TRUE(node.server.restartRequested());
    // Each under a challenge of its own.
    EXPECT_EQ(bus.sent(SeiCommand::Challenge), 3u);
    EXPECT_EQ(client.retransmissions(), 0u);
}

TEST(ConfigClientTest, ValuesTheNodeCannotTakeAreRefused)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    uint32_t sequence = 0;
    EXPECT_EQ(client.setNodeId(identity, keyOf(1), 255, sequence).status, SeiStatus::InvalidArgument);
    EXPECT_EQ(client.setBitRate(identity, keyOf(1), 33333, sequence).status, SeiStatus::InvalidArgument);
    EXPECT_EQ(node.backend.writes, 0u);
}

TEST(ConfigClientTest, AWrongKeyIsRefusedAndThreeLockTheNodeOut)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    uint32_t sequence = 0;
    for (int attempt = 0; attempt < 3; ++attempt) {
        const ConfigError refused = client.setNodeId(identity, keyOf(2), 9, sequence);
        EXPECT_EQ(refused.kind, ConfigError::Kind::Refused);
        EXPECT_EQ(refused.status, SeiStatus::BadMac);
    }
    // Now even the right key waits: the Challenge itself is refused.
    const ConfigError locked = client.setNodeId(identity, keyOf(1), 9, sequence);
    EXPECT_EQ(locked.kind, ConfigError::Kind::Refused);
    EXPECT_EQ(locked.status, SeiStatus::LockedOut);
    EXPECT_EQ(locked.lockoutSecondsLeft, 60);
    EXPECT_EQ(hostconfig::refusalText("node 3", locked.status, locked.lockoutSecondsLeft),
              "node 3 is locked out for 60 s after three wrong keys");
    EXPECT_EQ(node.backend.writes, 0u);
    EXPECT_TRUE(identified(client).lockedOut());
}

TEST(ConfigClientTest, ANodeWithoutAKeyRefusesEveryChange)
{
    MemoryNode node(4711, 3, std::nullopt);
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    EXPECT_FALSE(identity.hasKey());
    const ConfigError refused = client.restart(identity, keyOf(1));
    EXPECT_EQ(refused.kind, ConfigError::Kind::Refused);
    EXPECT_EQ(refused.status, SeiStatus::NoKey);
    EXPECT_FALSE(node.server.restartRequested());
}

TEST(ConfigClientTest, ALostReplyIsAskedAgainUnderANewChallenge)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    // The node writes, but its reply is lost. Sending the same bytes again
    // could only be refused (the challenge is used up), so the client asks
    // for a new challenge and signs again.
    bus.dropCommand = SeiCommand::SetNodeId;
    bus.dropReplies = 1;
    uint32_t sequence = 0;
    const ConfigError error = client.setNodeId(identity, keyOf(1), 9, sequence);
    ASSERT_FALSE(error) << error.why;
    EXPECT_EQ(sequence, 9u);
    EXPECT_EQ(node.backend.writes, 2u);
    EXPECT_EQ(bus.sent(SeiCommand::Challenge), 2u);
    EXPECT_EQ(bus.sent(SeiCommand::SetNodeId), 2u);
    EXPECT_EQ(client.retransmissions(), 1u);
}

TEST(ConfigClientTest, ALostChallengeIsAskedAgain)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    bus.dropCommand = SeiCommand::Challenge;
    bus.dropReplies = 2;
    uint32_t sequence = 0;
    ASSERT_FALSE(client.setBitRate(identity, keyOf(1), 125000, sequence));
    EXPECT_EQ(bus.sent(SeiCommand::Challenge), 3u);
    EXPECT_EQ(client.retransmissions(), 2u);
}

TEST(ConfigClientTest, ARestartIsNeverSentTwice)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    const NodeIdentity identity = identified(client);
    bus.dropCommand = SeiCommand::Restart;
    bus.dropReplies = 1;
    const ConfigError error = client.restart(identity, keyOf(1));
    EXPECT_EQ(error.kind, ConfigError::Kind::Silent);
    EXPECT_NE(error.why.find("restarting already"), std::string::npos) << error.why;
    EXPECT_EQ(bus.sent(SeiCommand::Restart), 1u);
    EXPECT_TRUE(node.server.restartRequested());
}

TEST(ConfigClientTest, ASilentNodeIsSilentAfterEveryRetry)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 4);
    ConfigClient client(bus, kOptions);
    NodeIdentity identity;
    const ConfigError error = client.identify(identity);
    EXPECT_EQ(error.kind, ConfigError::Kind::Silent);
    EXPECT_NE(error.why.find("4 attempts"), std::string::npos) << error.why;
    EXPECT_EQ(bus.requests.size(), 4u);
    EXPECT_EQ(client.retransmissions(), 3u);
}

TEST(ConfigClientTest, ANodeOfAnotherProtocolVersionIsNotSentAMac)
{
    MemoryNode node(4711, 3, keyOf(1));
    MemoryBus bus({&node}, 3);
    ConfigClient client(bus, kOptions);
    NodeIdentity identity = identified(client);
    identity.protocol = 2;
    uint32_t sequence = 0;
    EXPECT_EQ(client.setNodeId(identity, keyOf(1), 9, sequence).kind, ConfigError::Kind::Unexpected);
    EXPECT_EQ(bus.requests.size(), 1u);
}

// Three nodes, two of them fresh with the same CAN node number, and one
// without a serial number: the scan finds the serial numbers, and each
// node is reached alone through the broadcast address.
TEST(ConfigClientTest, AScanFindsNodesSharingACanNodeNumberAndEachIsConfiguredAlone)
{
    MemoryNode first(0xFFFFFFFF, 1, keyOf(1));
    MemoryNode second(1, 1, keyOf(2));
    MemoryNode other(0x00C0FFEE, 7, keyOf(3));
    MemoryNode unnumbered(0, 1, keyOf(4));
    std::vector<MemoryNode*> nodes{&first, &second, &other, &unnumbered};
    MemoryBus bus(nodes, config_test::kBroadcast);
    ConfigClient client(bus, kOptions);
    std::vector<uint32_t> serials;
    ASSERT_FALSE(client.scan(serials));
    EXPECT_EQ(serials, (std::vector<uint32_t>{1u, 0x00C0FFEEu, 0xFFFFFFFFu}));
    EXPECT_EQ(client.probes(), bus.probes);

    for (MemoryNode* node : {&second, &other, &first}) {
        hostconfig::SelectedNode selected;
        ASSERT_FALSE(client.select(node->backend.id.serial, selected));
        EXPECT_EQ(selected.canNode, node->backend.id.canNode);
        const NodeIdentity identity = identified(client);
        EXPECT_EQ(identity.serial, node->backend.id.serial);
        EXPECT_TRUE(identity.selected());
    }
    // The selected node alone takes a change sent to the broadcast address,
    // under its own key.
    const NodeIdentity identity = identified(client);
    ASSERT_EQ(identity.serial, 0xFFFFFFFFu);
    uint32_t sequence = 0;
    ASSERT_FALSE(client.setNodeId(identity, keyOf(1), 2, sequence));
    EXPECT_EQ(first.backend.configuration.nodeId, 2);
    EXPECT_EQ(second.backend.configuration.nodeId, 1);
    EXPECT_EQ(unnumbered.backend.configuration.nodeId, 1);

    ASSERT_FALSE(client.deselect());
    for (MemoryNode* node : nodes) {
        EXPECT_FALSE(node->server.selected());
    }
    // Nobody is selected: nothing but the scan's commands is answered there.
    NodeIdentity nobody;
    EXPECT_EQ(client.identify(nobody).kind, ConfigError::Kind::Silent);
    // A serial number nobody has: silence.
    hostconfig::SelectedNode selected;
    EXPECT_EQ(client.select(4711, selected).kind, ConfigError::Kind::Silent);
}

TEST(ConfigClientTest, AScanOfABusWithoutSerialNumbersFindsNothing)
{
    MemoryNode unnumbered(0, 1, keyOf(4));
    MemoryBus bus({&unnumbered}, config_test::kBroadcast);
    ConfigClient client(bus, kOptions);
    std::vector<uint32_t> serials{42};
    ASSERT_FALSE(client.scan(serials));
    EXPECT_TRUE(serials.empty());
    EXPECT_EQ(bus.probes, 1u);
}

} // namespace
