// The configuration protocol's messages (SeiMessage): every request and
// reply of docs/protocols/config.md survives a round trip, has the layout
// the page gives byte for byte, and is refused one byte shorter or longer.
#include <sei/SeiMessage.hpp>

#include "SeiTestSupport.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace {

using namespace sei_test;

SeiMessage reply(SeiCommand command, SeiStatus status = SeiStatus::Ok)
{
    SeiMessage m;
    m.kind = SeiMessageKind::Reply;
    m.command = command;
    m.status = status;
    return m;
}

void fillMac(SeiMessage& m)
{
    m.hasMac = true;
    for (size_t i = 0; i < sei::kSeiMacSize; ++i) {
        m.mac[i] = static_cast<uint8_t>(0xA0 + i);
    }
}

// Every field the message's command and kind carry, compared.
void expectSame(const SeiMessage& a, const SeiMessage& b)
{
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.command, b.command);
    EXPECT_EQ(a.status, b.status);
    EXPECT_EQ(a.lockoutSecondsLeft, b.lockoutSecondsLeft);
    EXPECT_EQ(a.hasMac, b.hasMac);
    EXPECT_EQ(0, std::memcmp(a.mac, b.mac, sizeof a.mac));
    EXPECT_EQ(a.nodeId, b.nodeId);
    EXPECT_EQ(a.canNode, b.canNode);
    EXPECT_EQ(a.board, b.board);
    EXPECT_EQ(a.serial, b.serial);
    EXPECT_EQ(a.protocol, b.protocol);
    EXPECT_EQ(a.flags, b.flags);
    EXPECT_EQ(a.bitRate, b.bitRate);
    EXPECT_EQ(a.configuredNodeId, b.configuredNodeId);
    EXPECT_EQ(std::string(a.text != nullptr ? a.text : "", a.textLength),
              std::string(b.text != nullptr ? b.text : "", b.textLength));
    EXPECT_EQ(0, std::memcmp(a.challenge, b.challenge, sizeof a.challenge));
    EXPECT_EQ(a.sequence, b.sequence);
    EXPECT_EQ(a.lockoutSeconds, b.lockoutSeconds);
    EXPECT_EQ(a.probeBits, b.probeBits);
    EXPECT_EQ(a.probeValue, b.probeValue);
}

// Encodes @p m, checks the bytes against @p expected, decodes them back to
// the same message, and refuses them one byte shorter and one byte longer.
void roundTrip(const SeiMessage& m, const Bytes& expected)
{
    const Bytes bytes = encoded(m);
    EXPECT_EQ(bytes, expected);
    SeiMessage back;
    ASSERT_TRUE(SeiMessage::decode(bytes.data(), bytes.size(), back));
    expectSame(back, m);
    SeiMessage untouched;
    EXPECT_FALSE(SeiMessage::decode(bytes.data(), bytes.size() - 1, untouched)) << "one byte shorter";
    Bytes longer = bytes;
    longer.push_back(0);
    EXPECT_FALSE(SeiMessage::decode(longer.data(), longer.size(), untouched)) << "one byte longer";
    EXPECT_EQ(untouched.command, SeiCommand::Identify) << "a refused message leaves the output alone";
}

Bytes withMac(Bytes bytes)
{
    for (size_t i = 0; i < sei::kSeiMacSize; ++i) {
        bytes.push_back(static_cast<uint8_t>(0xA0 + i));
    }
    return bytes;
}

TEST(SeiMessageTest, RequestsWithoutArguments)
{
    roundTrip(request(SeiCommand::Identify), {0x01});
    roundTrip(request(SeiCommand::Challenge), {0x02});
    roundTrip(request(SeiCommand::GetConfiguration), {0x03});
    roundTrip(request(SeiCommand::Deselect), {0x22});
}

TEST(SeiMessageTest, RequestsWithAMac)
{
    SeiMessage query = request(SeiCommand::GetConfiguration);
    fillMac(query);
    roundTrip(query, withMac({0x03}));

    SeiMessage node = setNodeId(0x0102);
    fillMac(node);
    roundTrip(node, withMac({0x10, 0x02, 0x01}));

    SeiMessage rate = setBitRate(500000);
    fillMac(rate);
    roundTrip(rate, withMac({0x11, 0x20, 0xA1, 0x07, 0x00}));

    SeiMessage restart = request(SeiCommand::Restart);
    fillMac(restart);
    roundTrip(restart, withMac({0x12}));
}

TEST(SeiMessageTest, ScanningRequests)
{
    roundTrip(probe(12, 0xABC00000), {0x20, 12, 0x00, 0x00, 0xC0, 0xAB});
    roundTrip(select(0x12345678), {0x21, 0x78, 0x56, 0x34, 0x12});
    EXPECT_EQ(encoded(probe(32, 0)).size(), 6u) << "fits an ISO-TP single frame with room to spare";
}

TEST(SeiMessageTest, AProbeOfMoreThanThirtyTwoBitsIsRefused)
{
    const uint8_t bytes[] = {0x20, 33, 0, 0, 0, 0};
    SeiMessage m;
    EXPECT_FALSE(SeiMessage::decode(bytes, sizeof bytes, m));
    EXPECT_EQ(sei::seiProbeMask(0), 0u);
    EXPECT_EQ(sei::seiProbeMask(1), 0x80000000u);
    EXPECT_EQ(sei::seiProbeMask(12), 0xFFF00000u);
    EXPECT_EQ(sei::seiProbeMask(32), 0xFFFFFFFFu);
}

TEST(SeiMessageTest, IdentifyReply)
{
    SeiMessage m = reply(SeiCommand::Identify);
    m.nodeId = 0x0105;
    m.canNode = 5;
    m.board = 1;
    m.serial = 0xCAFEF00D;
    m.flags = sei::kSeiIdentifyHasKey | sei::kSeiIdentifySelected;
    m.bitRate = 125000;
    m.configuredNodeId = 6;
    m.text = "0.1.0";
    m.textLength = 5;
    roundTrip(m, {0x81, 0x00, 0x05, 0x01, 0x05, 0x01, 0x0D, 0xF0, 0xFE, 0xCA, 0x01, 0x09, 0x48, 0xE8, 0x01, 0x00,
                  0x06, 0x00, 0x05, '0', '.', '1', '.', '0'});
    m.textLength = 0;
    roundTrip(m, {0x81, 0x00, 0x05, 0x01, 0x05, 0x01, 0x0D, 0xF0, 0xFE, 0xCA, 0x01, 0x09, 0x48, 0xE8, 0x01, 0x00,
                  0x06, 0x00, 0x00});
}

TEST(SeiMessageTest, TheLongestIdentifyReplyIsTheLargestMessage)
{
    const std::string text(sei::kSeiMaxText, 'v');
    SeiMessage m = reply(SeiCommand::Identify);
    m.text = text.c_str();
    m.textLength = static_cast<uint8_t>(text.size());
    EXPECT_EQ(encoded(m).size(), sei::kSeiMaxMessage);
    uint8_t small[sei::kSeiMaxMessage - 1];
    EXPECT_EQ(m.encode(small, sizeof small), 0u) << "does not fit";
}

TEST(SeiMessageTest, ChallengeReply)
{
    SeiMessage m = reply(SeiCommand::Challenge);
    Bytes expected = {0x82, 0x00};
    for (size_t i = 0; i < sei::kSeiChallengeSize; ++i) {
        m.challenge[i] = static_cast<uint8_t>(i * 7);
        expected.push_back(static_cast<uint8_t>(i * 7));
    }
    roundTrip(m, expected);
}

TEST(SeiMessageTest, GetConfigurationReply)
{
    SeiMessage m = reply(SeiCommand::GetConfiguration);
    m.sequence = 0x01020304;
    m.nodeId = 7;
    m.bitRate = 1000000;
    m.flags = sei::kSeiConfigurationQueriesClosed;
    m.lockoutSeconds = 300;
    m.text = "can0=1000000";
    m.textLength = 12;
    roundTrip(m, {0x83, 0x00, 0x04, 0x03, 0x02, 0x01, 0x07, 0x00, 0x40, 0x42, 0x0F, 0x00, 0x01, 0x2C, 0x01, 12, 'c',
                  'a', 'n', '0', '=', '1', '0', '0', '0', '0', '0', '0'});
}

TEST(SeiMessageTest, RepliesWithASequenceWritten)
{
    SeiMessage node = reply(SeiCommand::SetNodeId);
    node.sequence = 9;
    roundTrip(node, {0x90, 0x00, 0x09, 0x00, 0x00, 0x00});
    SeiMessage rate = reply(SeiCommand::SetBitRate);
    rate.sequence = 0xFFFFFFFF;
    roundTrip(rate, {0x91, 0x00, 0xFF, 0xFF, 0xFF, 0xFF});
}

TEST(SeiMessageTest, RepliesWithNothingMore)
{
    roundTrip(reply(SeiCommand::Restart), {0x92, 0x00});
    roundTrip(reply(SeiCommand::ProbeSerial), {0xA0, 0x00});
    roundTrip(reply(SeiCommand::Deselect), {0xA2, 0x00});
}

TEST(SeiMessageTest, SelectReply)
{
    SeiMessage m = reply(SeiCommand::Select);
    m.nodeId = 300;
    m.canNode = 44;
    roundTrip(m, {0xA1, 0x00, 0x2C, 0x01, 44});
}

TEST(SeiMessageTest, ARefusalCarriesOnlyItsStatusButALockoutItsSecondsLeft)
{
    for (const SeiCommand command : {SeiCommand::Identify, SeiCommand::Challenge, SeiCommand::GetConfiguration,
                                     SeiCommand::SetNodeId, SeiCommand::SetBitRate, SeiCommand::Restart,
                                     SeiCommand::ProbeSerial, SeiCommand::Select, SeiCommand::Deselect}) {
        const uint8_t code = static_cast<uint8_t>(static_cast<uint8_t>(command) | sei::kSeiReplyBit);
        roundTrip(reply(command, SeiStatus::Malformed), {code, 0x01});
        roundTrip(reply(command, SeiStatus::NotPermitted), {code, 0x0A});
        SeiMessage locked = reply(command, SeiStatus::LockedOut);
        locked.lockoutSecondsLeft = 0x0102;
        roundTrip(locked, {code, 0x06, 0x02, 0x01});
    }
}

TEST(SeiMessageTest, TheReplyToARequestThatCannotBeRead)
{
    SeiMessage m;
    m.kind = SeiMessageKind::Unreadable;
    m.status = SeiStatus::UnknownCommand;
    roundTrip(m, {0xFF, 0x02});
    m.status = SeiStatus::Malformed;
    roundTrip(m, {0xFF, 0x01});
}

TEST(SeiMessageTest, UnknownCodesAndStatusesAreRefused)
{
    SeiMessage m;
    for (const Bytes& bytes : {Bytes{}, Bytes{0x00}, Bytes{0x04}, Bytes{0x7F}, Bytes{0x84, 0x00}, Bytes{0x81, 11},
                               Bytes{0xFF, 11}, Bytes{0xFF}}) {
        EXPECT_FALSE(SeiMessage::decode(bytes.data(), bytes.size(), m)) << bytes.size();
    }
    EXPECT_FALSE(SeiMessage::decode(nullptr, 1, m));
}

TEST(SeiMessageTest, CommandsAndTheirMacs)
{
    EXPECT_TRUE(sei::isSeiCommand(0x01));
    EXPECT_TRUE(sei::isSeiCommand(0x22));
    EXPECT_FALSE(sei::isSeiCommand(0x23));
    EXPECT_FALSE(sei::isSeiCommand(0x81));
    EXPECT_TRUE(sei::seiCommandNeedsMac(SeiCommand::SetNodeId));
    EXPECT_TRUE(sei::seiCommandNeedsMac(SeiCommand::SetBitRate));
    EXPECT_TRUE(sei::seiCommandNeedsMac(SeiCommand::Restart));
    EXPECT_FALSE(sei::seiCommandNeedsMac(SeiCommand::GetConfiguration));
    EXPECT_FALSE(sei::seiCommandNeedsMac(SeiCommand::Select));
    EXPECT_STREQ(sei::seiStatusText(SeiStatus::NoKey),
                 "the node holds no configuration key: nothing can be changed over the bus");
}

} // namespace
