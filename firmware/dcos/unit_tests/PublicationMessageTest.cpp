// Host tests of publications over the network
// (docs/protocols/publications.md): the byte layout of the three parts and
// of a withdrawal, written out by hand from the specification, every
// refusal of the decoder, the reassembly of parts from one bus (torn and
// interleaved publications dropped, never mixed), and the duplicate filter
// that makes two buses deliver each publication once, against a model.
#include <dcos/internal/PublicationMessage.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <random>
#include <vector>

namespace {

using dcos::DsmPage;
using dcos::ObjectId;
using dcos::ObjectType;
using namespace dcos::internal;

using Frame = std::array<uint8_t, kPublicationFrameBytes>;
using Outcome = PublicationAssembler::Outcome;

DsmPage counting(uint8_t first)
{
    DsmPage page{};
    for (size_t i = 0; i < dcos::kDsmPageSize; ++i) {
        page.bytes[i] = static_cast<uint8_t>(first + i);
    }
    return page;
}

std::array<Frame, kPublicationFrames> encoded(uint16_t index, uint32_t dataId, const DsmPage& page)
{
    uint8_t frames[kPublicationFrames][kPublicationFrameBytes];
    encodePublication(index, dataId, page, frames);
    std::array<Frame, kPublicationFrames> out;
    for (size_t part = 0; part < kPublicationFrames; ++part) {
        std::copy(frames[part], frames[part] + kPublicationFrameBytes, out[part].begin());
    }
    return out;
}

PublicationPart decoded(const Frame& frame)
{
    PublicationPart part;
    EXPECT_EQ(decodePublicationPart(frame.data(), frame.size(), part), PublicationMessageError::None);
    return part;
}

TEST(PublicationMessageTest, APublicationIsThreeFramesOfHeaderSequenceAndPage)
{
    const auto frames = encoded(0xA53, 0x12345677, counting(0x10));
    // Part 0, tag 3 (0x...77 & 3), index 0xA53; sequence 0x5677; page 0-3.
    EXPECT_EQ(frames[0], (Frame{0x3A, 0x53, 0x56, 0x77, 0x10, 0x11, 0x12, 0x13}));
    // Part 1 (0x40), tag 3: page 4-9.
    EXPECT_EQ(frames[1], (Frame{0x7A, 0x53, 0x14, 0x15, 0x16, 0x17, 0x18, 0x19}));
    // Part 2 (0x80), tag 3: page 10-15.
    EXPECT_EQ(frames[2], (Frame{0xBA, 0x53, 0x1A, 0x1B, 0x1C, 0x1D, 0x1E, 0x1F}));
}

TEST(PublicationMessageTest, AWithdrawalIsTwoBytes)
{
    uint8_t frame[kWithdrawalBytes];
    encodeWithdrawal(0x0C1, frame);
    EXPECT_EQ(frame[0], 0xC0);
    EXPECT_EQ(frame[1], 0xC1);
    PublicationPart part;
    ASSERT_EQ(decodePublicationPart(frame, sizeof frame, part), PublicationMessageError::None);
    EXPECT_EQ(part.kind, PublicationPartKind::Withdrawal);
    EXPECT_EQ(part.index, 0x0C1);
}

TEST(PublicationMessageTest, TheIdsLowTwelveBitsTravelAndTheReceiverAddsNodeAndType)
{
    const ObjectId publisher(0x0203, ObjectType::DsmPublisher, 0x7FE);
    EXPECT_EQ(publicationIndexOf(publisher), 0x7FE);
    EXPECT_EQ(publisherOn(0x0203, 0x7FE), publisher);
}

TEST(PublicationMessageTest, TheDecoderRefusesWrongLengthsAndTags)
{
    const auto frames = encoded(1, 6, counting(0));
    PublicationPart part;
    for (size_t length : {size_t{0}, size_t{1}, size_t{2}, size_t{7}}) {
        EXPECT_EQ(decodePublicationPart(frames[0].data(), length, part), PublicationMessageError::WrongLength)
            << length;
    }
    const uint8_t longWithdrawal[8] = {0xC0, 0x01, 0, 0, 0, 0, 0, 0};
    EXPECT_EQ(decodePublicationPart(longWithdrawal, 8, part), PublicationMessageError::WrongLength);
    const uint8_t taggedWithdrawal[2] = {0xD0, 0x01};
    EXPECT_EQ(decodePublicationPart(taggedWithdrawal, 2, part), PublicationMessageError::WrongTag);
    Frame first = frames[0];
    first[3] ^= 1; // The sequence number no longer ends in the tag.
    EXPECT_EQ(decodePublicationPart(first.data(), first.size(), part), PublicationMessageError::WrongTag);
}

TEST(PublicationMessageTest, ThreePartsInTurnMakeThePage)
{
    const auto frames = encoded(5, 0x10002, counting(0x40));
    PublicationAssembler assembler;
    EXPECT_EQ(assembler.take(decoded(frames[0])), Outcome::Gathering);
    EXPECT_EQ(assembler.take(decoded(frames[1])), Outcome::Gathering);
    ASSERT_EQ(assembler.take(decoded(frames[2])), Outcome::Complete);
    EXPECT_EQ(assembler.sequence(), 0x0002);
    const DsmPage expected = counting(0x40);
    EXPECT_EQ(0, std::memcmp(assembler.page().bytes, expected.bytes, dcos::kDsmPageSize));
    EXPECT_EQ(assembler.take(decoded(frames[2])), Outcome::Dropped) << "a third part with nothing begun";
}

TEST(PublicationMessageTest, APartOutOfTurnOrOfAnotherPublicationIsDroppedNeverMixed)
{
    const auto older = encoded(5, 8, counting(0x00));
    const auto newer = encoded(5, 9, counting(0x80));
    PublicationAssembler assembler;
    // A lost second part: the third is out of turn.
    EXPECT_EQ(assembler.take(decoded(older[0])), Outcome::Gathering);
    EXPECT_EQ(assembler.take(decoded(older[2])), Outcome::Dropped);
    // Interleaved: the older publication's later parts carry the older tag.
    EXPECT_EQ(assembler.take(decoded(older[0])), Outcome::Gathering);
    EXPECT_EQ(assembler.take(decoded(newer[0])), Outcome::Gathering);
    EXPECT_EQ(assembler.take(decoded(older[1])), Outcome::Dropped);
    EXPECT_EQ(assembler.take(decoded(newer[1])), Outcome::Dropped) << "the newer one was dropped with it";
    // Begun again, the newer publication completes.
    EXPECT_EQ(assembler.take(decoded(newer[0])), Outcome::Gathering);
    EXPECT_EQ(assembler.take(decoded(newer[1])), Outcome::Gathering);
    EXPECT_EQ(assembler.take(decoded(newer[2])), Outcome::Complete);
    EXPECT_EQ(assembler.page().bytes[0], 0x80);
}

TEST(PublicationMessageTest, EveryRandomFrameStreamYieldsOnlyWholePagesThatWereSent)
{
    // Frames of many publications, some lost, duplicated or swapped: every
    // complete page the assembler yields is exactly one that was encoded
    // with that sequence number.
    std::mt19937 random(20261126);
    PublicationAssembler assembler;
    std::vector<Frame> stream;
    for (uint32_t dataId = 1; dataId < 3000; ++dataId) {
        for (const Frame& frame : encoded(9, dataId, counting(static_cast<uint8_t>(dataId * 7)))) {
            const unsigned roll = random() % 20;
            if (roll == 0) {
                continue; // Lost.
            }
            stream.push_back(frame);
            if (roll == 1) {
                stream.push_back(frame); // Duplicated.
            }
        }
        if (stream.size() >= 2 && random() % 10 == 0) {
            std::swap(stream[stream.size() - 1], stream[stream.size() - 2]);
        }
    }
    size_t complete = 0;
    for (const Frame& frame : stream) {
        if (assembler.take(decoded(frame)) != Outcome::Complete) {
            continue;
        }
        ++complete;
        // The page was sent with a data identifier ending in the sequence
        // number; the first byte tells which (dataId * 7, modulo 256).
        bool matches = false;
        for (uint32_t dataId = assembler.sequence(); dataId < 3000 && !matches; dataId += 0x10000) {
            const DsmPage expected = counting(static_cast<uint8_t>(dataId * 7));
            matches = std::memcmp(expected.bytes, assembler.page().bytes, dcos::kDsmPageSize) == 0;
        }
        EXPECT_TRUE(matches) << "sequence " << assembler.sequence();
    }
    EXPECT_GT(complete, 2000u);
}

TEST(PublicationMessageTest, TheFilterTakesEachPublicationOnceFromTwoBuses)
{
    PublicationFilter filter;
    uint64_t now = 5'000'000'000;
    EXPECT_TRUE(filter.take(100, now)) << "the first one";
    EXPECT_FALSE(filter.take(100, now)) << "the second bus's copy";
    EXPECT_TRUE(filter.take(101, now));
    EXPECT_TRUE(filter.take(103, now)) << "one lost on both buses: the next is newer";
    EXPECT_FALSE(filter.take(102, now)) << "a late copy from a slow bus is old";
    EXPECT_FALSE(filter.take(103, now + 5'000'000'000)) << "the same number never twice";
    // Up to half the sequence space ahead is newer; more is behind.
    EXPECT_TRUE(filter.take(103 + 32767, now));
    EXPECT_FALSE(filter.take(102, now)) << "32768 ahead, half way round, counts as behind";
    // Wrapping past 65535 is newer.
    EXPECT_TRUE(filter.take(65535, now));
    EXPECT_TRUE(filter.take(0, now));
    EXPECT_TRUE(filter.take(1, now));
    EXPECT_FALSE(filter.take(65535, now));
}

TEST(PublicationMessageTest, ANumberBehindAfterASilenceIsARestartedPublisher)
{
    PublicationFilter filter;
    const uint64_t now = 1'000'000'000;
    EXPECT_TRUE(filter.take(5000, now));
    EXPECT_FALSE(filter.take(1, now + PublicationFilter::kRestartSilenceNs - 1)) << "behind, too soon";
    EXPECT_TRUE(filter.take(1, now + PublicationFilter::kRestartSilenceNs)) << "the node restarted";
    EXPECT_TRUE(filter.take(2, now + PublicationFilter::kRestartSilenceNs));
    filter.reset();
    EXPECT_TRUE(filter.take(2, 0)) << "after a reset anything is new";
}

TEST(PublicationMessageTest, TheFilterAgreesWithAModelOfTwoBusesWithLossesAndLag)
{
    // Two buses deliver the same publications; each loses some, and the
    // second lags by up to four publications. Whatever arrives, the filter
    // takes a strictly increasing run of sequence numbers (no duplicate,
    // nothing old), and every publication one bus delivered before the
    // other had delivered anything newer is taken.
    std::mt19937 random(7);
    PublicationFilter filter;
    struct Delivery {
        uint32_t dataId;
    };
    std::vector<Delivery> arrivals;
    std::vector<uint32_t> laggingQueue;
    for (uint32_t dataId = 1; dataId < 200'000; ++dataId) {
        if (random() % 50 != 0) {
            arrivals.push_back({dataId});
        }
        if (random() % 50 != 0) {
            laggingQueue.push_back(dataId);
        }
        while (laggingQueue.size() > 4 || (!laggingQueue.empty() && random() % 3 == 0)) {
            arrivals.push_back({laggingQueue.front()});
            laggingQueue.erase(laggingQueue.begin());
        }
    }
    uint32_t lastTaken = 0;
    size_t taken = 0;
    for (const Delivery& delivery : arrivals) {
        const bool expected = delivery.dataId > lastTaken;
        EXPECT_EQ(filter.take(static_cast<uint16_t>(delivery.dataId), 0), expected) << delivery.dataId;
        if (expected) {
            lastTaken = delivery.dataId;
            ++taken;
        }
    }
    EXPECT_GT(taken, 190'000u) << "a publication is lost only when both buses lose it";
}

} // namespace

TEST(PublicationMessageTest, ARelayHeaderNamesTheNodeAndIsNoPublicationFrame)
{
    uint8_t header[kRelayHeaderBytes];
    encodeRelayHeader(0x0103, header);
    EXPECT_EQ(std::vector<uint8_t>(header, header + kRelayHeaderBytes), (std::vector<uint8_t>{0xFF, 0x00, 0x01, 0x03}));
    uint16_t node = 0;
    ASSERT_TRUE(decodeRelayHeader(header, kRelayHeaderBytes, node));
    EXPECT_EQ(node, 0x0103);
    PublicationPart part;
    EXPECT_NE(decodePublicationPart(header, kRelayHeaderBytes, part), PublicationMessageError::None);
    const uint8_t tooFar[kRelayHeaderBytes] = {0xFF, kRelayCrossings, 0x00, 0x03};
    EXPECT_FALSE(decodeRelayHeader(tooFar, kRelayHeaderBytes, node)) << "crossed more gateways than a frame may";
    // A frame relayed again counts the gateways it crossed before.
    encodeRelayHeader(0x0103, header, 2);
    EXPECT_EQ(std::vector<uint8_t>(header, header + kRelayHeaderBytes), (std::vector<uint8_t>{0xFF, 0x02, 0x01, 0x03}));
    uint8_t crossed = 0;
    ASSERT_TRUE(decodeRelayHeader(header, kRelayHeaderBytes, node, &crossed));
    EXPECT_EQ(crossed, 2);
    encodeRelayHeader(0x0103, header, 200);
    EXPECT_EQ(header[1], kRelayCrossings - 1) << "held to the last crossing";
    const uint8_t other[kRelayHeaderBytes] = {0xFE, 0x00, 0x00, 0x03};
    EXPECT_FALSE(decodeRelayHeader(other, kRelayHeaderBytes, node));
    EXPECT_FALSE(decodeRelayHeader(header, 3, node));
    const uint8_t longer[5] = {0xFF, 0x00, 0x00, 0x03, 0x00};
    EXPECT_FALSE(decodeRelayHeader(longer, 5, node));
}
