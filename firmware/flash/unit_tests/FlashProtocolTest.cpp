// The flash protocol on the host: its messages and frames, and a whole
// session against a card in memory, with a key made here.
#include <flash/FlashMessage.hpp>
#include <flash/FlashSession.hpp>
#include <flash/SerialFramer.hpp>

#include <boot/BootPlanner.hpp>
#include <boot/CardLayout.hpp>
#include <boot/Crc32.hpp>
#include <hostimage/ImageSigner.hpp>
#include <hostimage/SigningKey.hpp>
#include <image/ImageVerifier.hpp>

#include "FlashTestHost.hpp"

#include <image/Sha256.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace {

using namespace flash_test;

// -- messages and frames ----------------------------------------------------

TEST(FlashMessageTest, EveryTypeRoundTripsAndRefusesAByteMoreOrLess)
{
    const uint8_t block[3] = {7, 8, 9};
    std::vector<FlashMessage> messages;
    for (MessageType type : {MessageType::Hello, MessageType::Authenticate, MessageType::Begin, MessageType::Data,
                             MessageType::End, MessageType::Restart, MessageType::HelloReply,
                             MessageType::AuthenticateReply, MessageType::BeginReply, MessageType::DataReply,
                             MessageType::EndReply, MessageType::RestartReply, MessageType::ErrorReply}) {
        FlashMessage m;
        m.type = type;
        m.tag = 0x5A;
        m.status = FlashStatus::OutOfOrder;
        m.keyId[3] = 4;
        m.signature[63] = 9;
        m.header[255] = 1;
        m.sequence = 12;
        m.offset = 4096;
        m.length = sizeof block;
        m.crc = boot::crc32(block, sizeof block);
        m.bytes = block;
        m.node = 300;
        m.slotHolds[1] = true;
        m.slotVersion[1] = {1, 2, 3, 4};
        m.confirmedSlot = 0;
        m.slot = 1;
        messages.push_back(m);
    }
    for (const FlashMessage& m : messages) {
        const std::vector<uint8_t> bytes = encoded(m);
        FlashMessage decoded;
        ASSERT_TRUE(FlashMessage::decode(bytes.data(), bytes.size(), decoded)) << int(m.type);
        EXPECT_EQ(decoded.type, m.type);
        EXPECT_EQ(decoded.tag, 0x5A);
        EXPECT_EQ(encoded(decoded), bytes) << "one encoding per message, type " << int(m.type);
        FlashMessage ignored;
        EXPECT_FALSE(FlashMessage::decode(bytes.data(), bytes.size() - 1, ignored)) << int(m.type);
        std::vector<uint8_t> longer = bytes;
        longer.push_back(0);
        EXPECT_FALSE(FlashMessage::decode(longer.data(), longer.size(), ignored)) << int(m.type);
    }
    const uint8_t unknown[2] = {0x07, 0};
    FlashMessage ignored;
    EXPECT_FALSE(FlashMessage::decode(unknown, sizeof unknown, ignored));
    FlashMessage tooLong;
    tooLong.type = MessageType::Data;
    tooLong.length = flash::kMaxBlock + 1;
    uint8_t out[flash::kMaxMessage + 8];
    EXPECT_EQ(tooLong.encode(out, sizeof out), 0u);
}

TEST(SerialFramerTest, FindsFramesInNoiseAndDropsDamagedOnes)
{
    const uint8_t payload[5] = {1, 2, 3, 4, 5};
    uint8_t frame[64];
    const size_t length = flash::SerialFramer::frame(payload, sizeof payload, frame, sizeof frame);
    ASSERT_EQ(length, sizeof payload + flash::SerialFramer::kOverhead);
    std::vector<uint8_t> line = {'d', 'c', 'o', 's', '>', ' ', 0xD5, 0xD5};
    line.insert(line.end(), frame, frame + length);
    std::vector<uint8_t> damaged(frame, frame + length);
    damaged[6] ^= 1;
    line.insert(line.end(), damaged.begin(), damaged.end());
    line.insert(line.end(), frame, frame + length);
    flash::SerialFramer receiver;
    int frames = 0;
    for (const uint8_t byte : line) {
        if (receiver.receive(byte)) {
            ++frames;
            EXPECT_EQ(std::vector<uint8_t>(receiver.payload(), receiver.payload() + receiver.payloadLength()),
                      std::vector<uint8_t>(payload, payload + sizeof payload));
        }
    }
    EXPECT_EQ(frames, 2);
    EXPECT_EQ(receiver.dropped(), 1u);
    const uint8_t huge[4] = {0xD5, 0xC5, 0xFF, 0xFF};
    for (const uint8_t byte : huge) {
        EXPECT_FALSE(receiver.receive(byte));
    }
    EXPECT_EQ(receiver.dropped(), 2u) << "a length above the largest message";
    EXPECT_EQ(flash::SerialFramer::frame(payload, 0, frame, sizeof frame), 0u);
}

TEST(SerialFramerTest, AResetAbandonsAFrameASenderLeftUnfinished)
{
    const uint8_t payload[5] = {1, 2, 3, 4, 5};
    uint8_t frame[64];
    const size_t length = flash::SerialFramer::frame(payload, sizeof payload, frame, sizeof frame);
    flash::SerialFramer receiver;
    for (size_t i = 0; i < 6; ++i) {
        EXPECT_FALSE(receiver.receive(frame[i]));
    }
    EXPECT_TRUE(receiver.inFrame());
    receiver.reset();
    EXPECT_FALSE(receiver.inFrame());
    EXPECT_EQ(receiver.dropped(), 1u);
    bool completed = false;
    for (size_t i = 0; i < length; ++i) {
        completed = receiver.receive(frame[i]);
    }
    EXPECT_TRUE(completed) << "the next frame whole";
}

// -- a session against a card in memory --------------------------------------

class FlashSessionTest : public ::testing::Test {
protected:
    FlashSessionTest()
        : keys{trusted(signingKey(0))},
          session(store, keys, 1, identity(), reinterpret_cast<const uint8_t*>("seed"), 4), host(session, 5)
    {
    }

    static flash::SessionIdentity identity()
    {
        flash::SessionIdentity id;
        id.node = 5;
        return id;
    }

    FlashMessage hello() { return host.hello(); }
    FlashStatus authenticate(int key = 0, bool freshHello = true) { return host.authenticate(key, freshHello); }
    FlashMessage begin(const std::vector<uint8_t>& image) { return host.begin(image); }
    FlashMessage block(const std::vector<uint8_t>& image, uint32_t offset, uint32_t sequence, size_t length,
                       bool damage = false)
    {
        return host.block(image, offset, sequence, length, damage);
    }
    FlashMessage sendAll(const std::vector<uint8_t>& image, uint32_t from = 0)
    {
        const FlashMessage reply = host.sendAll(image, from);
        EXPECT_EQ(reply.status, FlashStatus::Ok);
        return reply;
    }
    FlashMessage simple(MessageType type) { return host.simple(type); }

    MemoryCard store;
    image::TrustedKey keys[1];
    flash::FlashSession session;
    FlashHost host;
};

TEST_F(FlashSessionTest, AWholeSessionLeavesAVerifiedImagePendingInTheSlot)
{
    const FlashMessage who = hello();
    EXPECT_EQ(who.node, 5);
    EXPECT_EQ(who.mode, flash::NodeMode::Recovery);
    EXPECT_FALSE(who.slotHolds[0]);
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> image = imageOf(5000, {1, 0, 0, 0});
    const FlashMessage started = begin(image);
    ASSERT_EQ(started.status, FlashStatus::Ok);
    EXPECT_EQ(started.slot, 0) << "nothing confirmed: slot A";
    EXPECT_EQ(started.offset, 0u);
    EXPECT_EQ(sendAll(image).offset, 5000u);
    ASSERT_EQ(simple(MessageType::End).status, FlashStatus::Ok);
    const unsigned writes = store.writes;
    EXPECT_EQ(simple(MessageType::End).status, FlashStatus::Ok) << "a repeated End, its reply lost";
    EXPECT_EQ(store.writes, writes) << "and nothing written twice";
    const std::optional<boot::BootState> state = store.state();
    ASSERT_TRUE(state.has_value());
    EXPECT_EQ(state->trial, boot::TrialState::Pending);
    EXPECT_EQ(state->trialSlot, 0);
    // The stage loader's view: the slot's header sector, then the payload.
    std::vector<uint8_t> onCard(store.bytes.begin() + card::kSlotLba[0] * 512,
                                store.bytes.begin() + card::kSlotLba[0] * 512 + 256);
    onCard.insert(onCard.end(), store.bytes.begin() + (card::kSlotLba[0] + 1) * 512,
                  store.bytes.begin() + (card::kSlotLba[0] + 1) * 512 + 5000);
    EXPECT_EQ(onCard, image);
    EXPECT_EQ(simple(MessageType::Restart).status, FlashStatus::Ok);
    flash::RestartTarget target{};
    EXPECT_TRUE(session.restartRequested(target));
}

TEST_F(FlashSessionTest, NothingChangesTheCardBeforeAuthentication)
{
    const std::vector<uint8_t> image = imageOf(600, {1, 0, 0, 0});
    EXPECT_EQ(begin(image).status, FlashStatus::NotAuthenticated);
    EXPECT_EQ(block(image, 0, 0, 512).status, FlashStatus::NotAuthenticated);
    EXPECT_EQ(simple(MessageType::End).status, FlashStatus::NotAuthenticated);
    EXPECT_EQ(simple(MessageType::Restart).status, FlashStatus::NotAuthenticated);
    EXPECT_EQ(authenticate(1), FlashStatus::AuthenticationFailed) << "a key the card does not trust";
    EXPECT_EQ(begin(image).status, FlashStatus::NotAuthenticated);
    EXPECT_EQ(store.writes, 0u);
    flash::RestartTarget target{};
    EXPECT_FALSE(session.restartRequested(target));
}

TEST_F(FlashSessionTest, AChallengeServesOneAttemptAndAHelloEndsTheSession)
{
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    EXPECT_EQ(authenticate(0, false), FlashStatus::AuthenticationFailed) << "the same signature again";
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    const FlashMessage first = host.lastHello;
    const FlashMessage second = hello();
    EXPECT_EQ(begin(imageOf(600, {1, 0, 0, 0})).status, FlashStatus::NotAuthenticated);
    EXPECT_FALSE(std::equal(std::begin(first.challenge), std::end(first.challenge), std::begin(second.challenge)))
        << "every Hello draws a new challenge";
}

TEST_F(FlashSessionTest, AnImageTheStageLoaderWouldRefuseIsRefusedAtBegin)
{
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    FlashMessage stranger = begin(imageOf(600, {1, 0, 0, 0}, 1));
    EXPECT_EQ(stranger.status, FlashStatus::ImageRefused);
    EXPECT_EQ(stranger.imageError, image::ImageError::UnknownKey);
    std::vector<uint8_t> altered = imageOf(600, {1, 0, 0, 0});
    altered[20] ^= 1;
    EXPECT_EQ(begin(altered).imageError, image::ImageError::BadSignature);
    EXPECT_EQ(store.writes, 0u);
}

TEST_F(FlashSessionTest, TheConfirmedSlotIsNeverWrittenAndADowngradeIsRefused)
{
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> first = imageOf(1500, {2, 0, 0, 0});
    ASSERT_EQ(begin(first).status, FlashStatus::Ok);
    sendAll(first);
    ASSERT_EQ(simple(MessageType::End).status, FlashStatus::Ok);
    // The stage loader boots and confirms it (as BootPlanner and BootControl would).
    boot::BootState confirmed = *store.state();
    confirmed.confirmedSlot = 0;
    confirmed.trial = boot::TrialState::None;
    confirmed.trialSlot = boot::BootState::kNoSlot;
    ++confirmed.sequence;
    uint8_t record[512];
    confirmed.encode(record);
    std::copy(record, record + 512, store.bytes.begin() + card::kBootStateLba * 512);
    std::copy(record, record + 512, store.bytes.begin() + (card::kBootStateLba + 1) * 512);
    EXPECT_EQ(begin(imageOf(1500, {1, 9, 0, 0})).imageError, image::ImageError::Downgrade);
    const FlashMessage next = begin(imageOf(1500, {2, 1, 0, 0}));
    EXPECT_EQ(next.status, FlashStatus::Ok);
    EXPECT_EQ(next.slot, 1) << "the slot that is not confirmed";
}

TEST_F(FlashSessionTest, BlocksMustComeInOrderWithTheirCrc)
{
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> image = imageOf(4000, {1, 0, 0, 0});
    ASSERT_EQ(begin(image).status, FlashStatus::Ok);
    EXPECT_EQ(block(image, 0, 0, 1024).status, FlashStatus::Ok);
    const FlashMessage skipped = block(image, 2048, 2, 1024);
    EXPECT_EQ(skipped.status, FlashStatus::OutOfOrder);
    EXPECT_EQ(skipped.offset, 1024u) << "where to go on";
    EXPECT_EQ(block(image, 1024, 5, 1024).status, FlashStatus::OutOfOrder) << "a wrong sequence number";
    EXPECT_EQ(block(image, 1024, 1, 1024, true).status, FlashStatus::BadBlockCrc);
    EXPECT_EQ(block(image, 1024, 1, 100).status, FlashStatus::Malformed) << "a part sector before the end";
    EXPECT_EQ(simple(MessageType::End).status, FlashStatus::NoTransfer) << "not every byte has arrived";
    EXPECT_EQ(block(image, 1024, 1, 1024).status, FlashStatus::Ok);
}

TEST_F(FlashSessionTest, ABeginWithTheSameHeaderResumesWhereTheTransferStopped)
{
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> image = imageOf(6000, {1, 0, 0, 0});
    ASSERT_EQ(begin(image).status, FlashStatus::Ok);
    block(image, 0, 0, 1024);
    block(image, 1024, 1, 1024);
    // The link dropped; a new session. Hello tells the host what it can resume.
    const FlashMessage held = hello();
    EXPECT_EQ(held.transferSlot, 0);
    EXPECT_EQ(held.transferOffset, 2048u);
    uint8_t headerDigest[32];
    image::Sha256::digest(image.data(), 256, headerDigest);
    EXPECT_TRUE(std::equal(std::begin(held.transferDigest), std::end(held.transferDigest), headerDigest))
        << "the SHA-256 of the transfer's header";
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    const FlashMessage resumed = begin(image);
    ASSERT_EQ(resumed.status, FlashStatus::Ok);
    EXPECT_EQ(resumed.offset, 2048u);
    sendAll(image, 2048);
    EXPECT_EQ(simple(MessageType::End).status, FlashStatus::Ok);
    // Another image starts over.
    ASSERT_EQ(begin(imageOf(3000, {1, 0, 1, 0})).offset, 0u);
    EXPECT_FALSE(store.state()->trial == boot::TrialState::Pending) << "the slot's pending trial was dropped";
}

TEST_F(FlashSessionTest, WhatTheCardHoldsCountsAtEnd)
{
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    const std::vector<uint8_t> image = imageOf(3000, {1, 0, 0, 0});
    ASSERT_EQ(begin(image).status, FlashStatus::Ok);
    sendAll(image);
    store.bytes[(card::kSlotLba[0] + 2) * 512 + 7] ^= 0x40; // The card lost a bit.
    const FlashMessage ended = simple(MessageType::End);
    EXPECT_EQ(ended.status, FlashStatus::ImageRefused);
    EXPECT_EQ(ended.imageError, image::ImageError::PayloadMismatch);
    EXPECT_FALSE(store.state().has_value()) << "nothing marked pending";
}

TEST_F(FlashSessionTest, ACardErrorIsReportedAndMalformedRequestsAnswered)
{
    ASSERT_EQ(authenticate(), FlashStatus::Ok);
    store.failing = true;
    EXPECT_EQ(begin(imageOf(600, {1, 0, 0, 0})).status, FlashStatus::CardError);
    const uint8_t garbage[3] = {0x04, 0x33, 0x00};
    uint8_t reply[64];
    const size_t length = session.handle(garbage, sizeof garbage, reply, sizeof reply);
    FlashMessage decoded;
    ASSERT_TRUE(FlashMessage::decode(reply, length, decoded));
    EXPECT_EQ(decoded.type, MessageType::ErrorReply);
    EXPECT_EQ(decoded.status, FlashStatus::Malformed);
    EXPECT_EQ(decoded.tag, 0x33);
}

} // namespace
