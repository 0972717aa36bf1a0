// The DCOS identifier layout: fields, arbitration order, and every refusal.
#include <can/MessageIdentifier.hpp>

#include <dcos/TaskAgent.hpp>

#include <gtest/gtest.h>

#include <random>

namespace {

using can::CanFrame;
using can::IdFormat;
using can::LinkError;
using can::MessageIdentifier;
using can::MessageType;

// The identifier carries the kernel's priorities unchanged.
static_assert(MessageIdentifier::kHighestPriority == dcos::kHighestPriority);
static_assert(MessageIdentifier::kLowestPriority == dcos::kLowestPriority);

constexpr MessageType kAssignedTypes[] = {
    MessageType::TimeSync,       MessageType::RemoteReply, MessageType::RemoteRequest, MessageType::DsmPublication,
    MessageType::Segmented,      MessageType::Configuration, MessageType::Monitoring, MessageType::Flashing,
};

TEST(MessageIdentifier, FieldsAtTheirBitPositions)
{
    const auto id = MessageIdentifier::make(0x15, MessageType::DsmPublication, 0xAB, 0xCD);
    ASSERT_TRUE(id.ok());
    EXPECT_EQ(id.value().encode(), (0x15u << 24) | (0x20u << 16) | (0xABu << 8) | 0xCDu);
    EXPECT_EQ(MessageIdentifier::kPriorityShift, 24u);
    EXPECT_EQ(MessageIdentifier::kTypeShift, 16u);
    EXPECT_EQ(MessageIdentifier::kDestinationShift, 8u);
    EXPECT_EQ(MessageIdentifier::kSourceShift, 0u);
}

TEST(MessageIdentifier, EveryPriorityTypeAndNodeRoundTrips)
{
    for (uint8_t priority = 0; priority <= MessageIdentifier::kLowestPriority; ++priority) {
        for (const MessageType type : kAssignedTypes) {
            for (unsigned node = 0; node <= MessageIdentifier::kMaxNodeNumber; node += 17) {
                const uint8_t destination = static_cast<uint8_t>(255 - node);
                const auto id = MessageIdentifier::make(priority, type, destination, static_cast<uint8_t>(node));
                ASSERT_TRUE(id.ok());
                const uint32_t raw = id.value().encode();
                ASSERT_LE(raw, CanFrame::kMaxExtendedId);
                const auto back = MessageIdentifier::decode(raw);
                ASSERT_TRUE(back.ok());
                EXPECT_EQ(back.value().priority(), priority);
                EXPECT_EQ(back.value().type(), type);
                EXPECT_EQ(back.value().destination(), destination);
                EXPECT_EQ(back.value().source(), node);
                EXPECT_EQ(back.value(), id.value());
                EXPECT_EQ(MessageIdentifier::priorityOf(raw), priority);
            }
        }
    }
}

TEST(MessageIdentifier, MoreUrgentPriorityAlwaysWinsArbitration)
{
    // On CAN the lower identifier wins; a lower priority number is more urgent.
    std::mt19937 random(15765);
    std::uniform_int_distribution<int> priority(0, 31);
    std::uniform_int_distribution<int> type(0, 6);
    std::uniform_int_distribution<int> node(0, 254);
    for (int i = 0; i < 20000; ++i) {
        const int a = priority(random);
        const int b = priority(random);
        if (a == b) {
            continue;
        }
        const uint32_t idA = MessageIdentifier::make(static_cast<uint8_t>(a), kAssignedTypes[type(random)],
                                                     static_cast<uint8_t>(node(random)),
                                                     static_cast<uint8_t>(node(random)))
                                 .value()
                                 .encode();
        const uint32_t idB = MessageIdentifier::make(static_cast<uint8_t>(b), kAssignedTypes[type(random)],
                                                     static_cast<uint8_t>(node(random)),
                                                     static_cast<uint8_t>(node(random)))
                                 .value()
                                 .encode();
        ASSERT_EQ(a < b, idA < idB) << a << " vs " << b;
    }
}

TEST(MessageIdentifier, TypeDecidesAtEqualPriority)
{
    for (size_t i = 1; i < sizeof(kAssignedTypes) / sizeof(kAssignedTypes[0]); ++i) {
        const uint32_t earlier = MessageIdentifier::make(9, kAssignedTypes[i - 1], 254, 254).value().encode();
        const uint32_t later = MessageIdentifier::make(9, kAssignedTypes[i], 0, 0).value().encode();
        EXPECT_LT(earlier, later) << can::messageTypeName(kAssignedTypes[i]);
    }
}

TEST(MessageIdentifier, SourceMakesEveryNodesIdentifierDistinct)
{
    const uint32_t fromOne = MessageIdentifier::make(4, MessageType::DsmPublication, 255, 1).value().encode();
    const uint32_t fromTwo = MessageIdentifier::make(4, MessageType::DsmPublication, 255, 2).value().encode();
    EXPECT_NE(fromOne, fromTwo);
}

TEST(MessageIdentifier, RefusedFields)
{
    EXPECT_EQ(MessageIdentifier::make(32, MessageType::TimeSync, 1, 2).error(), LinkError::InvalidPriority);
    EXPECT_EQ(MessageIdentifier::make(255, MessageType::TimeSync, 1, 2).error(), LinkError::InvalidPriority);
    EXPECT_EQ(MessageIdentifier::make(0, MessageType::TimeSync, 1, MessageIdentifier::kBroadcast).error(),
              LinkError::InvalidNodeNumber);
    EXPECT_EQ(MessageIdentifier::make(0, static_cast<MessageType>(0x02), 1, 2).error(),
              LinkError::UnassignedMessageType);
    EXPECT_TRUE(MessageIdentifier::make(0, MessageType::TimeSync, MessageIdentifier::kBroadcast, 254).ok());
}

TEST(MessageIdentifier, OnlyTheConfigurationProtocolSendsFromTheBroadcastAddress)
{
    // Its scans' answers and its selected node (docs/protocols/config.md, "Scanning").
    const can::LinkResult<MessageIdentifier> answer =
        MessageIdentifier::make(31, MessageType::Configuration, 254, MessageIdentifier::kBroadcast);
    ASSERT_TRUE(answer.ok());
    EXPECT_EQ(answer.value().encode(), 0x1F40FEFFu);
    EXPECT_TRUE(MessageIdentifier::decode(0x1F40FEFF).ok());
    for (const MessageType type : {MessageType::Flashing, MessageType::Monitoring, MessageType::RemoteReply,
                                   MessageType::NodeStarted}) {
        EXPECT_EQ(MessageIdentifier::make(31, type, 254, MessageIdentifier::kBroadcast).error(),
                  LinkError::InvalidNodeNumber);
    }
}

TEST(MessageIdentifier, OnlyTheListedTypesAreAssigned)
{
    int assigned = 0;
    for (unsigned raw = 0; raw <= 0xFF; ++raw) {
        const bool expected = raw == 0x01 || raw == 0x10 || raw == 0x11 || raw == 0x12 || raw == 0x13 || raw == 0x14
                              || raw == 0x20 || raw == 0x21 || raw == 0x30 || raw == 0x40 || raw == 0x41
                              || raw == 0x50;
        EXPECT_EQ(can::isAssignedMessageType(static_cast<uint8_t>(raw)), expected) << raw;
        const uint32_t id = (raw << MessageIdentifier::kTypeShift) | (1u << MessageIdentifier::kDestinationShift) | 2u;
        EXPECT_EQ(MessageIdentifier::decode(id).ok(), expected) << raw;
        if (!expected) {
            EXPECT_EQ(MessageIdentifier::decode(id).error(), LinkError::UnassignedMessageType);
            EXPECT_STREQ(can::messageTypeName(static_cast<MessageType>(raw)), "unassigned");
        }
        assigned += expected ? 1 : 0;
    }
    EXPECT_EQ(assigned, 12);
    EXPECT_STREQ(can::messageTypeName(MessageType::RemoteRequest), "remote request");
    EXPECT_STREQ(can::messageTypeName(MessageType::RelayedPublication), "relayed publication");
}

TEST(MessageIdentifier, DecodeRefusesIdentifiersBeyond29Bits)
{
    EXPECT_EQ(MessageIdentifier::decode(0x20000000).error(), LinkError::InvalidIdentifier);
    EXPECT_EQ(MessageIdentifier::decode(0xFFFFFFFF).error(), LinkError::InvalidIdentifier);
    EXPECT_EQ(MessageIdentifier::decode(0x0001FFFF).error(), LinkError::InvalidNodeNumber);
}

TEST(MessageIdentifier, FromFrameTakesOnlyExtendedDataFrames)
{
    const uint32_t raw = MessageIdentifier::make(3, MessageType::RemoteRequest, 7, 9).value().encode();
    const uint8_t data[2] = {1, 2};
    const auto extended = MessageIdentifier::fromFrame(CanFrame::makeData(raw, IdFormat::Extended, data, 2).value());
    ASSERT_TRUE(extended.ok());
    EXPECT_EQ(extended.value().encode(), raw);
    EXPECT_EQ(MessageIdentifier::fromFrame(CanFrame::makeData(0x123, IdFormat::Standard, data, 2).value()).error(),
              LinkError::NotExtendedFrame);
    EXPECT_EQ(MessageIdentifier::fromFrame(CanFrame::makeRemote(raw, IdFormat::Extended, 2).value()).error(),
              LinkError::UnexpectedRemoteFrame);
}

TEST(MessageIdentifier, ReversedAnswersTheSender)
{
    const auto request = MessageIdentifier::make(6, MessageType::Segmented, 0x20, 0x10).value();
    const auto answer = request.reversed();
    ASSERT_TRUE(answer.ok());
    EXPECT_EQ(answer.value().priority(), 6);
    EXPECT_EQ(answer.value().type(), MessageType::Segmented);
    EXPECT_EQ(answer.value().destination(), 0x10);
    EXPECT_EQ(answer.value().source(), 0x20);
    EXPECT_FALSE(answer.value().isBroadcast());

    const auto broadcast = MessageIdentifier::make(6, MessageType::DsmPublication, 255, 0x10).value();
    EXPECT_TRUE(broadcast.isBroadcast());
    EXPECT_EQ(broadcast.reversed().error(), LinkError::InvalidNodeNumber);
}

} // namespace
