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
    EXPECT_EQ(a.kernelStatus, b.kernelStatus);
    EXPECT_EQ(a.objectType, b.objectType);
    EXPECT_EQ(a.first, b.first);
    EXPECT_EQ(a.next, b.next);
    ASSERT_EQ(a.entryCount, b.entryCount);
    for (size_t i = 0; i < a.entryCount; ++i) {
        EXPECT_EQ(a.entries[i].id, b.entries[i].id);
        EXPECT_EQ(a.entries[i].owner, b.entries[i].owner);
        EXPECT_EQ(std::string(a.entries[i].name, a.entries[i].nameLength),
                  std::string(b.entries[i].name, b.entries[i].nameLength));
    }
    EXPECT_EQ(a.objectId, b.objectId);
    EXPECT_EQ(a.owner, b.owner);
    EXPECT_EQ(a.state, b.state);
    EXPECT_EQ(std::string(a.name != nullptr ? a.name : "", a.nameLength),
              std::string(b.name != nullptr ? b.name : "", b.nameLength));
    EXPECT_EQ(a.priority, b.priority);
    EXPECT_EQ(a.stackSize, b.stackSize);
    EXPECT_EQ(a.argument, b.argument);
    EXPECT_EQ(a.visibility, b.visibility);
    EXPECT_EQ(a.parameters[0], b.parameters[0]);
    EXPECT_EQ(a.parameters[1], b.parameters[1]);
    EXPECT_EQ(a.count, b.count);
    ASSERT_EQ(a.valueCount, b.valueCount);
    for (size_t i = 0; i < a.valueCount; ++i) {
        EXPECT_EQ(a.values[i], b.values[i]);
    }
    EXPECT_EQ(a.uptimeNs, b.uptimeNs);
    EXPECT_EQ(a.taskSwitches, b.taskSwitches);
    EXPECT_EQ(a.stackFree, b.stackFree);
    ASSERT_EQ(a.tableCount, b.tableCount);
    for (size_t i = 0; i < a.tableCount; ++i) {
        EXPECT_EQ(a.tables[i].type, b.tables[i].type);
        EXPECT_EQ(a.tables[i].used, b.tables[i].used);
        EXPECT_EQ(a.tables[i].capacity, b.tables[i].capacity);
    }
    EXPECT_EQ(a.delayMs, b.delayMs);
    EXPECT_EQ(a.leaseSeconds, b.leaseSeconds);
    EXPECT_EQ(a.periodMs, b.periodMs);
    EXPECT_EQ(a.monitorFlags, b.monitorFlags);
    ASSERT_EQ(a.channelCount, b.channelCount);
    for (size_t i = 0; i < a.channelCount; ++i) {
        EXPECT_EQ(a.channels[i].publisher, b.channels[i].publisher);
        EXPECT_EQ(a.channels[i].offset, b.channels[i].offset);
        EXPECT_EQ(a.channels[i].format, b.channels[i].format);
    }
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

TEST(SeiMessageTest, TheLongestSetConfigurationIsTheLargestMessage)
{
    const std::string text(sei::kSeiMaxText, 'v');
    SeiMessage m = request(SeiCommand::SetConfiguration);
    fillMac(m);
    m.text = text.c_str();
    m.textLength = static_cast<uint8_t>(text.size());
    EXPECT_EQ(encoded(m).size(), sei::kSeiMaxMessage);
    uint8_t small[sei::kSeiMaxMessage - 1];
    EXPECT_EQ(m.encode(small, sizeof small), 0u) << "does not fit";
    SeiMessage identify = reply(SeiCommand::Identify);
    identify.text = text.c_str();
    identify.textLength = static_cast<uint8_t>(text.size());
    EXPECT_LT(encoded(identify).size(), sei::kSeiMaxMessage);
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
    for (const SeiCommand command :
         {SeiCommand::Identify, SeiCommand::Challenge, SeiCommand::GetConfiguration, SeiCommand::SetNodeId,
          SeiCommand::SetBitRate, SeiCommand::Restart, SeiCommand::ProbeSerial, SeiCommand::Select,
          SeiCommand::Deselect, SeiCommand::ActivateBitRate, SeiCommand::ListObjects, SeiCommand::FindObject,
          SeiCommand::ObjectInfo, SeiCommand::NodeStatistics, SeiCommand::Monitor, SeiCommand::SetConfiguration,
          SeiCommand::CreateTask, SeiCommand::StartTask, SeiCommand::StopTask, SeiCommand::KillTask,
          SeiCommand::CreateObject, SeiCommand::DeleteObject, SeiCommand::AddObjects}) {
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
    for (const Bytes& bytes : {Bytes{}, Bytes{0x00}, Bytes{0x09}, Bytes{0x7F}, Bytes{0x89, 0x00}, Bytes{0x81, 12},
                               Bytes{0xFF, 12}, Bytes{0xFF}, Bytes{0x24}, Bytes{0x37, 0, 0}}) {
        EXPECT_FALSE(SeiMessage::decode(bytes.data(), bytes.size(), m)) << bytes.size();
    }
    EXPECT_FALSE(SeiMessage::decode(nullptr, 1, m));
}

TEST(SeiMessageTest, CommandsAndTheirMacs)
{
    EXPECT_TRUE(sei::isSeiCommand(0x01));
    EXPECT_TRUE(sei::isSeiCommand(0x22));
    EXPECT_TRUE(sei::isSeiCommand(0x23));
    EXPECT_FALSE(sei::isSeiCommand(0x24));
    EXPECT_FALSE(sei::isSeiCommand(0x37));
    EXPECT_FALSE(sei::isSeiCommand(0x81));
    EXPECT_TRUE(sei::seiCommandNeedsMac(SeiCommand::SetNodeId));
    EXPECT_TRUE(sei::seiCommandNeedsMac(SeiCommand::SetBitRate));
    EXPECT_TRUE(sei::seiCommandNeedsMac(SeiCommand::Restart));
    EXPECT_FALSE(sei::seiCommandNeedsMac(SeiCommand::GetConfiguration));
    EXPECT_FALSE(sei::seiCommandNeedsMac(SeiCommand::Select));
    for (const SeiCommand change : {SeiCommand::SetConfiguration, SeiCommand::CreateTask, SeiCommand::StartTask,
                                    SeiCommand::StopTask, SeiCommand::KillTask, SeiCommand::CreateObject,
                                    SeiCommand::DeleteObject, SeiCommand::AddObjects}) {
        EXPECT_TRUE(sei::seiCommandNeedsMac(change));
        EXPECT_FALSE(sei::seiCommandIsQuery(change));
        EXPECT_FALSE(sei::seiCommandIsBroadcast(change));
    }
    for (const SeiCommand query : {SeiCommand::GetConfiguration, SeiCommand::ListObjects, SeiCommand::FindObject,
                                   SeiCommand::ObjectInfo, SeiCommand::NodeStatistics, SeiCommand::Monitor}) {
        EXPECT_FALSE(sei::seiCommandNeedsMac(query));
        EXPECT_TRUE(sei::seiCommandIsQuery(query));
    }
    for (const SeiCommand broadcast :
         {SeiCommand::ProbeSerial, SeiCommand::Select, SeiCommand::Deselect, SeiCommand::ActivateBitRate}) {
        EXPECT_TRUE(sei::seiCommandIsBroadcast(broadcast));
        EXPECT_FALSE(sei::seiCommandNeedsMac(broadcast));
    }
    EXPECT_FALSE(sei::seiCommandIsBroadcast(SeiCommand::Identify));
    EXPECT_STREQ(sei::seiStatusText(SeiStatus::NoKey),
                 "the node holds no configuration key: nothing can be changed over the bus");
}

// The management commands (docs/protocols/config.md, "Objects and tasks").

TEST(SeiMessageTest, ObjectQueries)
{
    SeiMessage list = request(SeiCommand::ListObjects);
    list.objectType = 10;
    list.first = 0x0102;
    roundTrip(list, {0x04, 10, 0x02, 0x01});
    fillMac(list);
    roundTrip(list, withMac({0x04, 10, 0x02, 0x01}));

    SeiMessage find = request(SeiCommand::FindObject);
    find.objectType = 8;
    find.name = "speed";
    find.nameLength = 5;
    roundTrip(find, {0x05, 8, 5, 's', 'p', 'e', 'e', 'd'});

    SeiMessage info = request(SeiCommand::ObjectInfo);
    info.objectId = 0x0005A001;
    roundTrip(info, {0x06, 0x01, 0xA0, 0x05, 0x00});
    roundTrip(request(SeiCommand::NodeStatistics), {0x07});
}

TEST(SeiMessageTest, ANameLongerThanFifteenIsMalformed)
{
    SeiMessage m;
    const Bytes bytes = {0x05, 8, 16, 'a', 'b', 'c', 'd', 'e', 'f', 'g', 'h', 'i', 'j', 'k', 'l', 'm', 'n', 'o', 'p'};
    EXPECT_FALSE(SeiMessage::decode(bytes.data(), bytes.size(), m));
}

TEST(SeiMessageTest, ListObjectsReply)
{
    SeiMessage m = reply(SeiCommand::ListObjects);
    m.next = 9;
    m.entryCount = 2;
    m.entries[0] = {0x00051001, 0, "root", 4};
    m.entries[1] = {0x00051002, 0x00051001, "", 0};
    roundTrip(m, {0x84, 0x00, 0x09, 0x00, 2, 0x01, 0x10, 0x05, 0x00, 0, 0, 0, 0, 4, 'r', 'o', 'o', 't', 0x02, 0x10,
                  0x05, 0x00, 0x01, 0x10, 0x05, 0x00, 0});
    Bytes tooMany = {0x84, 0x00, 0xFF, 0xFF, 9};
    EXPECT_FALSE(SeiMessage::decode(tooMany.data(), tooMany.size(), m));
}

TEST(SeiMessageTest, ObjectInfoReply)
{
    SeiMessage m = reply(SeiCommand::ObjectInfo);
    m.objectType = 1;
    m.state = 5;
    m.visibility = 2;
    m.owner = 0;
    m.name = "pid";
    m.nameLength = 3;
    m.valueCount = 2;
    m.values[0] = 8;
    m.values[1] = 0x0102030405060708ull;
    roundTrip(m, {0x86, 0x00, 1, 5, 2, 0, 0, 0, 0, 3, 'p', 'i', 'd', 2, 8, 0, 0, 0, 0, 0, 0, 0, 0x08, 0x07, 0x06, 0x05,
                  0x04, 0x03, 0x02, 0x01});
}

TEST(SeiMessageTest, NodeStatisticsReply)
{
    SeiMessage m = reply(SeiCommand::NodeStatistics);
    m.uptimeNs = 0x100000002ull;
    m.taskSwitches = 3;
    m.stackFree = 4;
    m.tableCount = 1;
    m.tables[0] = {10, 5, 64};
    roundTrip(m, {0x87, 0x00, 2, 0, 0, 0, 1, 0, 0, 0, 3, 0, 0, 0, 4, 0, 0, 0, 1, 10, 5, 0, 64, 0});
}

TEST(SeiMessageTest, MonitorRequest)
{
    SeiMessage m = request(SeiCommand::Monitor);
    m.leaseSeconds = 30;
    m.periodMs = 100;
    m.monitorFlags = sei::kSeiMonitorLog;
    m.channelCount = 2;
    m.channels[0] = {0x00058001, 0, sei::SeiSampleFormat::I32};
    m.channels[1] = {0x00058002, 14, sei::SeiSampleFormat::U16};
    roundTrip(m, {0x08, 30, 0, 100, 0, 1, 2, 0x01, 0x80, 0x05, 0x00, 0, 5, 0x02, 0x80, 0x05, 0x00, 14, 2});
    Bytes pastThePage = {0x08, 30, 0, 100, 0, 0, 1, 0x01, 0x80, 0x05, 0x00, 13, 4};
    EXPECT_FALSE(SeiMessage::decode(pastThePage.data(), pastThePage.size(), m)) << "four bytes from 13";
    Bytes badFormat = {0x08, 30, 0, 100, 0, 0, 1, 0x01, 0x80, 0x05, 0x00, 0, 6};
    EXPECT_FALSE(SeiMessage::decode(badFormat.data(), badFormat.size(), m));
    Bytes badFlags = {0x08, 30, 0, 100, 0, 2, 0};
    EXPECT_FALSE(SeiMessage::decode(badFlags.data(), badFlags.size(), m));
    Bytes nineChannels = {0x08, 30, 0, 100, 0, 0, 9};
    EXPECT_FALSE(SeiMessage::decode(nineChannels.data(), nineChannels.size(), m));
}

TEST(SeiMessageTest, SetConfigurationRequest)
{
    SeiMessage m = request(SeiCommand::SetConfiguration);
    m.nodeId = 7;
    m.bitRate = 500000;
    m.flags = sei::kSeiConfigurationQueriesClosed;
    m.lockoutSeconds = 90;
    m.text = "x=1";
    m.textLength = 3;
    fillMac(m);
    roundTrip(m, withMac({0x13, 7, 0, 0x20, 0xA1, 0x07, 0x00, 1, 90, 0, 3, 'x', '=', '1'}));
    Bytes unknownFlag = withMac({0x13, 7, 0, 0x20, 0xA1, 0x07, 0x00, 2, 90, 0, 0});
    EXPECT_FALSE(SeiMessage::decode(unknownFlag.data(), unknownFlag.size(), m));
}

TEST(SeiMessageTest, TaskAndObjectCommands)
{
    SeiMessage create = request(SeiCommand::CreateTask);
    create.text = "sampler";
    create.textLength = 7;
    create.name = "s2";
    create.nameLength = 2;
    create.priority = 9;
    create.stackSize = 4096;
    create.argument = 0x11223344;
    fillMac(create);
    roundTrip(create, withMac({0x30, 7, 's', 'a', 'm', 'p', 'l', 'e', 'r', 2, 's', '2', 9, 0x00, 0x10, 0x00, 0x00,
                               0x44, 0x33, 0x22, 0x11}));

    for (const SeiCommand command :
         {SeiCommand::StartTask, SeiCommand::StopTask, SeiCommand::KillTask, SeiCommand::DeleteObject}) {
        SeiMessage m = request(command);
        m.objectId = 0x00051003;
        fillMac(m);
        roundTrip(m, withMac({static_cast<uint8_t>(command), 0x03, 0x10, 0x05, 0x00}));
    }

    SeiMessage object = request(SeiCommand::CreateObject);
    object.objectType = 10;
    object.name = "lock";
    object.nameLength = 4;
    object.visibility = 1;
    object.parameters[0] = 1;
    object.parameters[1] = sei::kSeiSemaphoreInheritance;
    fillMac(object);
    roundTrip(object, withMac({0x34, 10, 4, 'l', 'o', 'c', 'k', 1, 1, 0, 0, 0, 2, 0, 0, 0}));

    SeiMessage add = request(SeiCommand::AddObjects);
    add.objectType = 1;
    add.count = 8;
    fillMac(add);
    roundTrip(add, withMac({0x36, 1, 8, 0}));

    SeiMessage activate = request(SeiCommand::ActivateBitRate);
    activate.delayMs = 500;
    roundTrip(activate, {0x23, 0xF4, 0x01});
}

TEST(SeiMessageTest, RepliesWithAnId)
{
    for (const SeiCommand command : {SeiCommand::FindObject, SeiCommand::CreateTask, SeiCommand::CreateObject}) {
        SeiMessage m = reply(command);
        m.objectId = 0x0005A003;
        roundTrip(m, {static_cast<uint8_t>(static_cast<uint8_t>(command) | 0x80), 0x00, 0x03, 0xA0, 0x05, 0x00});
    }
    SeiMessage written = reply(SeiCommand::SetConfiguration);
    written.sequence = 12;
    roundTrip(written, {0x93, 0x00, 12, 0, 0, 0});
    for (const SeiCommand command : {SeiCommand::StartTask, SeiCommand::StopTask, SeiCommand::KillTask,
                                     SeiCommand::DeleteObject, SeiCommand::AddObjects, SeiCommand::Monitor}) {
        roundTrip(reply(command), {static_cast<uint8_t>(static_cast<uint8_t>(command) | 0x80), 0x00});
    }
}

TEST(SeiMessageTest, AKernelRefusalCarriesTheKernelsStatus)
{
    SeiMessage m = reply(SeiCommand::CreateObject, SeiStatus::KernelRefused);
    m.kernelStatus = 4; // TableFull
    roundTrip(m, {0xB4, 11, 4});
    EXPECT_STREQ(sei::seiStatusText(SeiStatus::KernelRefused), "the node's kernel refused it");
}

} // namespace
