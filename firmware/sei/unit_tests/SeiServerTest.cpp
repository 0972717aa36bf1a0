// The node's side of the configuration protocol (SeiServer): every command
// on a backend in memory, and each refusal docs/protocols/config.md
// names: no key, no challenge, a replay, a stale challenge, a wrong key,
// the lockout after three wrong MACs and its end, a right MAC resetting
// the count, closed queries, invalid values, a failing card.
#include <sei/SeiServer.hpp>

#include "SeiTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using namespace sei_test;

class SeiServerTest : public ::testing::Test {
protected:
    explicit SeiServerTest(std::optional<Key> key = keyOf(0x11), uint16_t lockoutSeconds = 0,
                           bool queriesClosed = false)
        : node(key, 0x12345678, lockoutSeconds, queriesClosed), host(carrier(), keyOf(0x11), 5, 0x12345678)
    {
    }

    SeiHost::Carrier carrier() { return serverCarrier(node.server, now); }

    /// The reply to @p bytes, or none.
    std::optional<Bytes> answer(const Bytes& bytes) { return carrier()(bytes); }

    uint64_t now = 1000 * kSecond;
    Node node;
    SeiHost host;
};

TEST_F(SeiServerTest, IdentifyTellsWhoTheNodeIsByteForByte)
{
    EXPECT_EQ(host.raw({0x01}), (Bytes{0x81, 0x00, 0x05, 0x00, 0x05, 0x01, 0x78, 0x56, 0x34, 0x12, 0x01, 0x01, 0x90,
                                       0xD0, 0x03, 0x00, 0x05, 0x00, 0x05, '0', '.', '1', '.', '0'}))
        << "node 5, CAN node 5, isa486, serial 0x12345678, protocol 1, has a key, 250 kbit/s, configured node 5";
}

TEST_F(SeiServerTest, ChallengeDrawsANewChallengeEachTime)
{
    const Bytes first = host.raw({0x02});
    const Bytes second = host.raw({0x02});
    ASSERT_EQ(first.size(), 18u);
    ASSERT_EQ(second.size(), 18u);
    EXPECT_EQ(first[0], 0x82);
    EXPECT_EQ(first[1], 0x00);
    EXPECT_NE(first, second);
}

TEST_F(SeiServerTest, GetConfigurationReadsTheCardWhenQueriesAreOpen)
{
    const Bytes expected = {0x83, 0x00, 0x07, 0x00, 0x00, 0x00, 0x05, 0x00, 0x90, 0xD0, 0x03, 0x00, 0x00, 0x00,
                            0x00, 24,   'c',  'a',  'n',  '0',  '=',  '2',  '5',  '0',  '0',  '0',  '0',  ' ',
                            'c',  'o',  'n',  's',  'o',  'l',  'e',  '=',  'c',  'o',  'm',  '1'};
    EXPECT_EQ(host.raw({0x03}), expected);
    // A MAC that comes is checked, and a right one changes nothing.
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    EXPECT_EQ(host.raw(host.signedBytes(request(SeiCommand::GetConfiguration))), expected);
}

TEST_F(SeiServerTest, SetNodeIdWithARightMacWritesTheConfiguration)
{
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    EXPECT_EQ(host.raw(host.signedBytes(setNodeId(9))), (Bytes{0x90, 0x00, 0x08, 0x00, 0x00, 0x00}))
        << "the sequence written, 8";
    EXPECT_EQ(node.backend.configuration.nodeId, 9);
    EXPECT_EQ(node.backend.writes, 1u);
    // Identify still tells the running node id, and the configured one.
    const SeiMessage who = host.ask(request(SeiCommand::Identify));
    EXPECT_EQ(who.nodeId, 5);
    EXPECT_EQ(who.configuredNodeId, 9);
}

TEST_F(SeiServerTest, SetBitRateWithARightMacWritesTheConfiguration)
{
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    EXPECT_EQ(host.raw(host.signedBytes(setBitRate(500000))), (Bytes{0x91, 0x00, 0x08, 0x00, 0x00, 0x00}));
    EXPECT_EQ(node.backend.configuration.bitRate, 500000u);
}

TEST_F(SeiServerTest, RestartAnswersAndAsksTheCallerToRestart)
{
    EXPECT_FALSE(node.server.restartRequested());
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    EXPECT_EQ(host.raw(host.signedBytes(request(SeiCommand::Restart))), (Bytes{0x92, 0x00}));
    EXPECT_TRUE(node.server.restartRequested());
}

TEST_F(SeiServerTest, ARestartTheBackendRefusesIsNotRequested)
{
    node.backend.restartStatus = SeiStatus::CardError;
    EXPECT_EQ(host.authenticated(request(SeiCommand::Restart)).status, SeiStatus::CardError);
    EXPECT_FALSE(node.server.restartRequested());
}

TEST_F(SeiServerTest, ProbeSerialIsAnsweredOnlyWhenTheTopBitsMatch)
{
    EXPECT_EQ(answer(encoded(probe(0, 0))), (Bytes{0xA0, 0x00})) << "no bit compared: every node with a serial";
    EXPECT_EQ(answer(encoded(probe(8, 0x12000000))), (Bytes{0xA0, 0x00}));
    EXPECT_EQ(answer(encoded(probe(32, 0x12345678))), (Bytes{0xA0, 0x00}));
    EXPECT_FALSE(answer(encoded(probe(8, 0x13000000))).has_value());
    EXPECT_FALSE(answer(encoded(probe(32, 0x12345679))).has_value());
    EXPECT_FALSE(answer(encoded(probe(4, 0x12000000))).has_value()) << "a value bit below the compared ones";
    EXPECT_EQ(answer({0x20, 33, 0, 0, 0, 0}), (Bytes{0xA0, 0x01})) << "33 bits: malformed";
}

TEST_F(SeiServerTest, ANodeWithoutASerialNumberNeverAnswersAScan)
{
    node.backend.id.serial = 0;
    EXPECT_FALSE(answer(encoded(probe(0, 0))).has_value());
    EXPECT_FALSE(answer(encoded(select(0))).has_value());
    EXPECT_FALSE(node.server.selected());
}

TEST_F(SeiServerTest, SelectAndDeselect)
{
    EXPECT_EQ(answer(encoded(select(0x12345678))), (Bytes{0xA1, 0x00, 0x05, 0x00, 0x05}));
    EXPECT_TRUE(node.server.selected());
    EXPECT_EQ(host.ask(request(SeiCommand::Identify)).flags, sei::kSeiIdentifyHasKey | sei::kSeiIdentifySelected);
    EXPECT_FALSE(answer(encoded(select(0x12345679))).has_value()) << "another node's serial: silent";
    EXPECT_FALSE(node.server.selected()) << "and deselected";
    EXPECT_TRUE(answer(encoded(select(0x12345678))).has_value());
    EXPECT_FALSE(answer({0x22}).has_value()) << "no node answers Deselect";
    EXPECT_FALSE(node.server.selected());
}

class SeiServerWithoutKeyTest : public SeiServerTest {
protected:
    SeiServerWithoutKeyTest() : SeiServerTest(std::nullopt) {}
};

TEST_F(SeiServerWithoutKeyTest, EveryCommandThatNeedsAMacIsRefusedWithNoKeyBeforeTheChallenge)
{
    // No challenge was drawn: NoKey still comes first.
    EXPECT_EQ(host.raw(host.signedBytes(setNodeId(9))), (Bytes{0x90, 0x07}));
    EXPECT_EQ(host.raw(host.signedBytes(setBitRate(500000))), (Bytes{0x91, 0x07}));
    EXPECT_EQ(host.raw(host.signedBytes(request(SeiCommand::Restart))), (Bytes{0x92, 0x07}));
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok) << "Challenge is always open";
    EXPECT_EQ(host.askSigned(setNodeId(9)).status, SeiStatus::NoKey);
    EXPECT_EQ(node.backend.writes, 0u);
    EXPECT_FALSE(node.server.restartRequested());
    EXPECT_EQ(host.ask(request(SeiCommand::Identify)).flags, 0) << "no key flag";
    EXPECT_EQ(host.raw({0x03}).at(1), 0x00) << "open queries need no key";
}

TEST_F(SeiServerTest, ACommandWithoutAChallengeIsRefused)
{
    EXPECT_EQ(host.raw(host.signedBytes(setNodeId(9))), (Bytes{0x90, 0x03}));
    EXPECT_EQ(node.backend.writes, 0u);
}

TEST_F(SeiServerTest, AReplayedCommandFindsNoChallengeOrAnotherOne)
{
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    const Bytes recorded = host.signedBytes(setNodeId(9));
    EXPECT_EQ(host.raw(recorded).at(1), 0x00);
    EXPECT_EQ(host.raw(recorded), (Bytes{0x90, 0x03})) << "the challenge is used up";
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    EXPECT_EQ(host.raw(recorded), (Bytes{0x90, 0x05})) << "another challenge: the MAC is wrong";
    EXPECT_EQ(node.backend.writes, 1u);
}

TEST_F(SeiServerTest, AWrongAttemptUsesTheChallengeUpToo)
{
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    Bytes altered = host.signedBytes(setNodeId(9));
    const Bytes right = host.signedBytes(setNodeId(9));
    altered[1] = 10; // another node id under the same MAC
    EXPECT_EQ(host.raw(altered), (Bytes{0x90, 0x05}));
    EXPECT_EQ(host.raw(right), (Bytes{0x90, 0x03}));
    EXPECT_EQ(node.backend.writes, 0u);
}

TEST_F(SeiServerTest, AChallengeOlderThanThirtySecondsIsStaleAndUsedUp)
{
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    now += 30 * kSecond;
    EXPECT_EQ(host.askSigned(setNodeId(9)).status, SeiStatus::Ok) << "30 s exactly still serves";
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    now += 30 * kSecond + 1;
    const Bytes late = host.signedBytes(setNodeId(10));
    EXPECT_EQ(host.raw(late), (Bytes{0x90, 0x04}));
    EXPECT_EQ(host.raw(late), (Bytes{0x90, 0x03}));
    EXPECT_EQ(node.backend.configuration.nodeId, 9);
}

TEST_F(SeiServerTest, AWrongKeyIsABadMac)
{
    host.setKey(keyOf(0x12));
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::BadMac);
    EXPECT_EQ(host.authenticated(request(SeiCommand::Restart)).status, SeiStatus::BadMac);
    EXPECT_EQ(node.backend.writes, 0u);
    EXPECT_FALSE(node.server.restartRequested());
}

TEST_F(SeiServerTest, ThreeWrongMacsLockTheNodeOutUntilTheLockoutEnds)
{
    host.setKey(keyOf(0x12));
    for (int attempt = 0; attempt < 3; ++attempt) {
        EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::BadMac);
    }
    EXPECT_EQ(host.raw({0x02}), (Bytes{0x82, 0x06, 60, 0x00})) << "Challenge: locked out, 60 s left";
    EXPECT_EQ(host.raw(host.signedBytes(setNodeId(9))), (Bytes{0x90, 0x06, 60, 0x00}));
    EXPECT_EQ(host.ask(request(SeiCommand::Identify)).flags, sei::kSeiIdentifyHasKey | sei::kSeiIdentifyLockedOut);
    EXPECT_EQ(host.raw({0x03}).at(1), 0x00) << "open queries stay open";
    now += 59 * kSecond + 500 * kMs;
    EXPECT_EQ(host.raw({0x02}), (Bytes{0x82, 0x06, 1, 0x00})) << "half a second left counts as one";
    host.setKey(keyOf(0x11));
    EXPECT_EQ(host.askSigned(setNodeId(9)).status, SeiStatus::LockedOut) << "even the right key";
    now += 500 * kMs;
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::Ok) << "the lockout is over";
    EXPECT_EQ(node.backend.configuration.nodeId, 9);
}

TEST_F(SeiServerTest, ARightMacResetsTheCount)
{
    host.setKey(keyOf(0x12));
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::BadMac);
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::BadMac);
    host.setKey(keyOf(0x11));
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::Ok);
    EXPECT_EQ(node.authenticator.badMacs(), 0u);
    host.setKey(keyOf(0x12));
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::BadMac);
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::BadMac);
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok) << "two wrong in a row: not locked out";
    EXPECT_EQ(host.askSigned(setNodeId(9)).status, SeiStatus::BadMac);
    EXPECT_EQ(host.challenge().status, SeiStatus::LockedOut) << "the third in a row";
}

TEST_F(SeiServerTest, StaleAndMissingChallengesDoNotCountTowardsTheLockout)
{
    for (int attempt = 0; attempt < 5; ++attempt) {
        EXPECT_EQ(host.askSigned(setNodeId(9)).status, SeiStatus::NoChallenge);
    }
    EXPECT_EQ(node.authenticator.badMacs(), 0u);
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
}

class SeiServerShortLockoutTest : public SeiServerTest {
protected:
    SeiServerShortLockoutTest() : SeiServerTest(keyOf(0x11), 10) {}
};

TEST_F(SeiServerShortLockoutTest, TheConfiguredLockoutHolds)
{
    host.setKey(keyOf(0x12));
    for (int attempt = 0; attempt < 3; ++attempt) {
        EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::BadMac);
    }
    EXPECT_EQ(host.raw({0x02}), (Bytes{0x82, 0x06, 10, 0x00}));
    now += 10 * kSecond;
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
}

class SeiServerClosedQueriesTest : public SeiServerTest {
protected:
    SeiServerClosedQueriesTest() : SeiServerTest(keyOf(0x11), 0, true) {}
};

TEST_F(SeiServerClosedQueriesTest, GetConfigurationNeedsAMac)
{
    EXPECT_EQ(host.raw({0x03}), (Bytes{0x83, 0x0A}));
    EXPECT_EQ(host.ask(request(SeiCommand::Identify)).flags, sei::kSeiIdentifyHasKey | sei::kSeiIdentifyQueriesClosed)
        << "Identify stays open";
    const SeiMessage configuration = host.authenticated(request(SeiCommand::GetConfiguration));
    EXPECT_EQ(configuration.status, SeiStatus::Ok);
    EXPECT_EQ(configuration.flags, sei::kSeiConfigurationQueriesClosed);
    EXPECT_EQ(configuration.sequence, 7u);
    host.setKey(keyOf(0x12));
    EXPECT_EQ(host.authenticated(request(SeiCommand::GetConfiguration)).status, SeiStatus::BadMac);
}

TEST_F(SeiServerClosedQueriesTest, ClosedQueriesOnANodeWithoutAKeyAnswerNoKey)
{
    Node keyless(std::nullopt, 0x12345678, 0, true);
    Bytes reply(sei::kSeiMaxMessage);
    const uint8_t bytes[] = {0x03};
    ASSERT_EQ(keyless.server.handle(bytes, 1, reply.data(), reply.size(), now), 2u);
    EXPECT_EQ(reply[1], static_cast<uint8_t>(SeiStatus::NoKey));
}

TEST_F(SeiServerTest, ValuesTheNodeCannotTakeAreRefused)
{
    for (const uint16_t id : {0, 255, 256, 0xFFFF}) {
        EXPECT_EQ(host.authenticated(setNodeId(id)).status, SeiStatus::InvalidArgument) << id;
    }
    EXPECT_EQ(host.authenticated(setNodeId(1)).status, SeiStatus::Ok);
    EXPECT_EQ(host.authenticated(setNodeId(254)).status, SeiStatus::Ok);
    for (const uint32_t rate : {0u, 123456u, 4000000u}) {
        EXPECT_EQ(host.authenticated(setBitRate(rate)).status, SeiStatus::InvalidArgument) << rate;
    }
    EXPECT_EQ(node.backend.writes, 2u);
    EXPECT_EQ(node.backend.configuration.bitRate, 250000u);
}

TEST_F(SeiServerTest, AFailingCardChangesNothing)
{
    node.backend.failing = true;
    EXPECT_EQ(host.authenticated(setNodeId(9)).status, SeiStatus::CardError);
    EXPECT_EQ(host.authenticated(setBitRate(500000)).status, SeiStatus::CardError);
    EXPECT_EQ(host.raw({0x01}), (Bytes{0x81, 0x09}));
    EXPECT_EQ(host.raw({0x03}), (Bytes{0x83, 0x09}));
    EXPECT_EQ(node.backend.configuration.nodeId, 5);
    EXPECT_EQ(node.backend.configuration.bitRate, 250000u);
    EXPECT_EQ(node.authenticator.badMacs(), 0u) << "the MACs were right";
}

TEST_F(SeiServerTest, RequestsThatCannotBeReadAreRefused)
{
    EXPECT_EQ(host.raw({}), (Bytes{0xFF, 0x01})) << "empty";
    EXPECT_EQ(host.raw({0x09}), (Bytes{0xFF, 0x02})) << "no such command";
    EXPECT_EQ(host.raw({0x81, 0x00}), (Bytes{0xFF, 0x02})) << "a reply is no request";
    EXPECT_EQ(host.raw({0x01, 0x00}), (Bytes{0x81, 0x01})) << "Identify one byte longer";
    EXPECT_EQ(host.raw({0x03, 0x00}), (Bytes{0x83, 0x01})) << "GetConfiguration with part of a MAC";
    EXPECT_EQ(host.raw({0x21, 0x78, 0x56, 0x34}), (Bytes{0xA1, 0x01})) << "Select one byte shorter";
    EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
    Bytes shorter = host.signedBytes(setNodeId(9));
    shorter.pop_back();
    EXPECT_EQ(host.raw(shorter), (Bytes{0x90, 0x01}));
    EXPECT_EQ(host.askSigned(setNodeId(9)).status, SeiStatus::Ok) << "a malformed request uses no challenge";
}

TEST_F(SeiServerTest, AReplyThatDoesNotFitIsNotWritten)
{
    uint8_t reply[10];
    const uint8_t identify[] = {0x01};
    EXPECT_EQ(node.server.handle(identify, 1, reply, sizeof reply, now), 0u);
}

} // namespace
