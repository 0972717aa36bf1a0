// Host tests of the remote transaction messages
// (docs/protocols/remote-transactions.md): the byte layout of requests and
// replies, written out by hand from the specification, every refusal of the
// decoders, and the time-out conversion both ways.
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/RemoteMessage.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <random>
#include <type_traits>
#include <vector>

namespace {

using dcos::Status;
using namespace dcos::internal;

using Bytes = std::array<uint8_t, kRemoteMessageBytes>;

// The bytes the encoder writes for a request or a reply.
template <typename Message>
Bytes encoded(const Message& message)
{
    uint8_t bytes[kRemoteMessageBytes];
    if constexpr (std::is_same_v<Message, RemoteRequest>) {
        encodeRequest(message, bytes);
    } else {
        encodeReply(message, bytes);
    }
    Bytes out;
    std::copy(bytes, bytes + kRemoteMessageBytes, out.begin());
    return out;
}

TEST(RemoteMessageTest, ARequestIsServiceTransactionObjectAndArgumentBigEndian)
{
    RemoteRequest request;
    request.service = RemoteService::PostEvent;
    request.transaction = 0xA3;
    request.object = 0x1234;
    request.argument = 0x89ABCDEF;
    EXPECT_EQ(encoded(request), (Bytes{0x04, 0xA3, 0x12, 0x34, 0x89, 0xAB, 0xCD, 0xEF}));
    RemoteRequest back;
    const Bytes bytes = encoded(request);
    ASSERT_EQ(decodeRequest(bytes.data(), bytes.size(), back), RemoteMessageError::None);
    EXPECT_EQ(back.service, RemoteService::PostEvent);
    EXPECT_EQ(back.transaction, 0xA3);
    EXPECT_EQ(back.object, 0x1234);
    EXPECT_EQ(back.argument, 0x89ABCDEFu);
    EXPECT_EQ(back.objectOn(7).raw(), 0x00071234u);
}

TEST(RemoteMessageTest, AReplyIsServiceTransactionStatusFlagsAndValueBigEndian)
{
    RemoteReply reply;
    reply.service = RemoteService::SemaphoreGetCount;
    reply.transaction = 0x15;
    reply.status = Status::WouldBlock;
    reply.pending = true;
    reply.value = 0x01020304;
    EXPECT_EQ(encoded(reply), (Bytes{0x03, 0x15, 0x08, 0x01, 0x01, 0x02, 0x03, 0x04}));
    RemoteReply back;
    const Bytes bytes = encoded(reply);
    ASSERT_EQ(decodeReply(bytes.data(), bytes.size(), back), RemoteMessageError::None);
    EXPECT_EQ(back.service, RemoteService::SemaphoreGetCount);
    EXPECT_EQ(back.transaction, 0x15);
    EXPECT_EQ(back.status, Status::WouldBlock);
    EXPECT_TRUE(back.pending);
    EXPECT_EQ(back.value, 0x01020304u);
}

TEST(RemoteMessageTest, EveryServiceAndStatusSurvivesTheRoundTrip)
{
    std::mt19937 random(14);
    for (uint8_t service = 1; service <= kLastRemoteService; ++service) {
        for (uint8_t status = 0; status <= dcos::kLastStatusValue; ++status) {
            RemoteReply reply;
            reply.service = static_cast<RemoteService>(service);
            reply.transaction = static_cast<uint8_t>(random());
            reply.status = static_cast<Status>(status);
            reply.pending = (random() & 1) != 0;
            reply.value = static_cast<uint32_t>(random());
            const Bytes bytes = encoded(reply);
            RemoteReply back;
            ASSERT_EQ(decodeReply(bytes.data(), bytes.size(), back), RemoteMessageError::None);
            EXPECT_EQ(encoded(back), bytes);
        }
        EXPECT_STRNE(remoteServiceName(static_cast<RemoteService>(service)), "?");
    }
}

TEST(RemoteMessageTest, TheDecodersRefuseWhatNoNodeSends)
{
    RemoteRequest request;
    RemoteReply reply;
    const Bytes good{0x02, 0x01, 0x30, 0x05, 0, 0, 0, 0};
    for (size_t length : {0u, 1u, 7u, 9u}) {
        EXPECT_EQ(decodeRequest(good.data(), length, request), RemoteMessageError::WrongLength) << length;
        EXPECT_EQ(decodeReply(good.data(), length, reply), RemoteMessageError::WrongLength) << length;
    }
    for (uint8_t service : {uint8_t{0}, uint8_t{kLastRemoteService + 1}, uint8_t{0xFF}}) {
        Bytes bad = good;
        bad[0] = service;
        EXPECT_EQ(decodeRequest(bad.data(), bad.size(), request), RemoteMessageError::UnknownService);
        EXPECT_EQ(decodeReply(bad.data(), bad.size(), reply), RemoteMessageError::UnknownService);
    }
    Bytes nullObject = good;
    nullObject[2] = nullObject[3] = 0;
    EXPECT_EQ(decodeRequest(nullObject.data(), nullObject.size(), request), RemoteMessageError::NullObject);
    const Bytes goodReply{0x02, 0x01, 0x00, 0x00, 0, 0, 0, 0};
    ASSERT_EQ(decodeReply(goodReply.data(), goodReply.size(), reply), RemoteMessageError::None);
    Bytes badStatus = goodReply;
    badStatus[2] = dcos::kLastStatusValue + 1;
    EXPECT_EQ(decodeReply(badStatus.data(), badStatus.size(), reply), RemoteMessageError::UnknownStatus);
    Bytes badFlags = goodReply;
    badFlags[3] = 0x02;
    EXPECT_EQ(decodeReply(badFlags.data(), badFlags.size(), reply), RemoteMessageError::ReservedBits);
    EXPECT_STREQ(remoteMessageErrorName(RemoteMessageError::ReservedBits), "reserved bits set");
}

TEST(RemoteMessageTest, ANodesAnnouncementIsItsIdBigEndianThenZeros)
{
    // docs/protocols/remote-transactions.md, "A node that starts again".
    uint8_t bytes[kRemoteMessageBytes];
    encodeNodeStarted(NodeStarted{0x1234}, bytes);
    const Bytes expected{0x12, 0x34, 0, 0, 0, 0, 0, 0};
    EXPECT_TRUE(std::equal(expected.begin(), expected.end(), bytes));
    NodeStarted decoded;
    ASSERT_EQ(decodeNodeStarted(bytes, sizeof bytes, decoded), RemoteMessageError::None);
    EXPECT_EQ(decoded.node, 0x1234);
}

TEST(RemoteMessageTest, AnAnnouncementOfNoNodeOrWithMoreThanTheIdIsRefused)
{
    NodeStarted decoded;
    const uint8_t good[kRemoteMessageBytes] = {0, 7, 0, 0, 0, 0, 0, 0};
    EXPECT_EQ(decodeNodeStarted(good, 7, decoded), RemoteMessageError::WrongLength);
    for (size_t byte = 2; byte < kRemoteMessageBytes; ++byte) {
        uint8_t bytes[kRemoteMessageBytes];
        std::memcpy(bytes, good, sizeof bytes);
        bytes[byte] = 1;
        EXPECT_EQ(decodeNodeStarted(bytes, sizeof bytes, decoded), RemoteMessageError::ReservedBits) << byte;
    }
    const uint8_t none[kRemoteMessageBytes] = {};
    EXPECT_EQ(decodeNodeStarted(none, sizeof none, decoded), RemoteMessageError::UnknownNode);
    const uint8_t broadcast[kRemoteMessageBytes] = {0xFF, 0xFF, 0, 0, 0, 0, 0, 0};
    EXPECT_EQ(decodeNodeStarted(broadcast, sizeof broadcast, decoded), RemoteMessageError::UnknownNode);
}

TEST(RemoteMessageTest, TimeOutsTravelAsWholeMillisecondsNeverShorter)
{
    EXPECT_EQ(remoteTimeoutMs(dcos::kPoll), kRemotePoll);
    EXPECT_EQ(remoteTimeoutMs(dcos::kWaitForever), kRemoteForever);
    EXPECT_EQ(remoteTimeoutMs(1), 1u);
    EXPECT_EQ(remoteTimeoutMs(1'000'000), 1u);
    EXPECT_EQ(remoteTimeoutMs(1'000'001), 2u);
    EXPECT_EQ(remoteTimeoutMs(uint64_t{kRemoteForever} * 1'000'000), kRemoteForever - 1);
    EXPECT_EQ(remoteTimeoutNs(kRemoteForever), dcos::kWaitForever);
    EXPECT_EQ(remoteTimeoutNs(250), 250'000'000u);
    EXPECT_EQ(remoteTimeoutNs(kRemotePoll), dcos::kPoll);
}

} // namespace

namespace {

using dcos::ObjectType;

using Frame = std::array<uint8_t, kRemoteMessageBytes>;

std::array<Frame, kNameQueryFrames> nameQuery(uint8_t type, uint8_t transaction, const char* name)
{
    uint8_t frames[kNameQueryFrames][kRemoteMessageBytes];
    encodeNameQuery(type, transaction, name, frames);
    std::array<Frame, kNameQueryFrames> out;
    for (size_t part = 0; part < kNameQueryFrames; ++part) {
        std::copy(frames[part], frames[part] + kRemoteMessageBytes, out[part].begin());
    }
    return out;
}

NameQueryPart decodedPart(const Frame& frame)
{
    NameQueryPart part;
    EXPECT_EQ(decodeNameQueryPart(frame.data(), frame.size(), part), NameQueryError::None);
    return part;
}

TEST(NameQueryTest, AQueryIsThreeFramesOfPartTypeTransactionAndTheNamePadded)
{
    const auto frames = nameQuery(static_cast<uint8_t>(ObjectType::DsmPublisher), 0x5A, "tank.level");
    EXPECT_EQ(frames[0], (Frame{0x08, 0x5A, 't', 'a', 'n', 'k', '.', 'l'}));
    EXPECT_EQ(frames[1], (Frame{0x48, 0x5A, 'e', 'v', 'e', 'l', 0, 0}));
    EXPECT_EQ(frames[2], (Frame{0x88, 0x5A, 0, 0, 0, 0, 0, 0}));
    NameQueryAssembler assembler;
    EXPECT_FALSE(assembler.take(decodedPart(frames[0])));
    EXPECT_FALSE(assembler.take(decodedPart(frames[1])));
    ASSERT_TRUE(assembler.take(decodedPart(frames[2])));
    EXPECT_STREQ(assembler.name(), "tank.level");
    EXPECT_EQ(assembler.type(), static_cast<uint8_t>(ObjectType::DsmPublisher));
    EXPECT_EQ(assembler.transaction(), 0x5A);
}

TEST(NameQueryTest, AFifteenCharacterNameFillsTheFieldAndALongerOneIsCut)
{
    const auto frames = nameQuery(static_cast<uint8_t>(ObjectType::Task), 1, "abcdefghijklmnopq");
    EXPECT_EQ(frames[2], (Frame{0x81, 0x01, 'm', 'n', 'o', 0, 0, 0}));
    NameQueryAssembler assembler;
    for (const Frame& frame : frames) {
        (void)assembler.take(decodedPart(frame));
    }
    EXPECT_STREQ(assembler.name(), "abcdefghijklmno");
}

TEST(NameQueryTest, TheDecoderRefusesWhatNoNodeSends)
{
    const auto frames = nameQuery(static_cast<uint8_t>(ObjectType::Semaphore), 7, "pump");
    NameQueryPart part;
    EXPECT_EQ(decodeNameQueryPart(frames[0].data(), 7, part), NameQueryError::WrongLength);
    Frame bad = frames[0];
    bad[0] = 0xCA; // Part 3.
    EXPECT_EQ(decodeNameQueryPart(bad.data(), bad.size(), part), NameQueryError::ReservedBits);
    bad = frames[0];
    bad[0] |= 0x10;
    EXPECT_EQ(decodeNameQueryPart(bad.data(), bad.size(), part), NameQueryError::ReservedBits);
    bad = frames[2];
    bad[7] = 1;
    EXPECT_EQ(decodeNameQueryPart(bad.data(), bad.size(), part), NameQueryError::ReservedBits);
    bad = frames[2];
    bad[6] = kNameRelays + 1; // More relays than a routed request has hops.
    EXPECT_EQ(decodeNameQueryPart(bad.data(), bad.size(), part), NameQueryError::ReservedBits);
    for (ObjectType type : {ObjectType::None, ObjectType::Process, ObjectType::DsmSubscription,
                            ObjectType::NetworkInterface, ObjectType::Module, ObjectType::Reserved15}) {
        bad = frames[0];
        bad[0] = static_cast<uint8_t>(type);
        EXPECT_EQ(decodeNameQueryPart(bad.data(), bad.size(), part), NameQueryError::BadType)
            << static_cast<int>(type);
    }
}

TEST(NameQueryTest, ARelayedQueryCarriesItsRelaysLeftInPartTwosByteSixNotInTheName)
{
    uint8_t frames[kNameQueryFrames][kRemoteMessageBytes];
    encodeNameQuery(static_cast<uint8_t>(ObjectType::Semaphore), 9, "abcdefghijklmno", frames, 2);
    EXPECT_EQ(Frame(std::to_array(frames[2])), (Frame{0x8A, 0x09, 'm', 'n', 'o', 0, 2, 0}));
    NameQueryAssembler assembler;
    for (const uint8_t(&frame)[kRemoteMessageBytes] : frames) {
        NameQueryPart part;
        ASSERT_EQ(decodeNameQueryPart(frame, kRemoteMessageBytes, part), NameQueryError::None);
        (void)assembler.take(part);
    }
    EXPECT_STREQ(assembler.name(), "abcdefghijklmno") << "the relay count is not read as a name byte";
    EXPECT_EQ(assembler.relays(), 2);
    // A count above the most is held to it when encoded; a plain query carries 0.
    encodeNameQuery(static_cast<uint8_t>(ObjectType::Semaphore), 9, "pump", frames, 200);
    EXPECT_EQ(frames[2][6], kNameRelays);
    EXPECT_EQ(nameQuery(static_cast<uint8_t>(ObjectType::Semaphore), 9, "pump")[2][6], 0);
}

TEST(NameQueryTest, PartsOutOfTurnOrOfAnotherQueryAndMalformedNamesMakeNoQuery)
{
    const auto one = nameQuery(static_cast<uint8_t>(ObjectType::Task), 1, "first");
    const auto two = nameQuery(static_cast<uint8_t>(ObjectType::Task), 2, "second");
    NameQueryAssembler assembler;
    EXPECT_FALSE(assembler.take(decodedPart(one[0])));
    EXPECT_FALSE(assembler.take(decodedPart(two[1]))) << "another transaction";
    EXPECT_FALSE(assembler.take(decodedPart(one[2]))) << "what was gathered was dropped";
    EXPECT_FALSE(assembler.take(decodedPart(one[1])));
    // An empty name, and a name with a character after its NUL.
    const auto empty = nameQuery(static_cast<uint8_t>(ObjectType::Task), 3, "");
    for (size_t part = 0; part < kNameQueryFrames; ++part) {
        const bool complete = assembler.take(decodedPart(empty[part]));
        EXPECT_FALSE(complete);
    }
    auto gap = nameQuery(static_cast<uint8_t>(ObjectType::Task), 4, "ab");
    gap[1][2] = 'x';
    bool complete = false;
    for (const Frame& frame : gap) {
        complete = assembler.take(decodedPart(frame));
    }
    EXPECT_FALSE(complete);
}

} // namespace

namespace {

using Frames = std::array<std::vector<uint8_t>, kPortSendFrames>;

Frames portSendFrames(const PortSendRequest& request)
{
    uint8_t frames[kPortSendFrames][kRemoteMessageBytes];
    uint8_t lengths[kPortSendFrames];
    encodePortSend(request, frames, lengths);
    Frames out;
    for (size_t part = 0; part < kPortSendFrames; ++part) {
        out[part].assign(frames[part], frames[part] + lengths[part]);
    }
    return out;
}

PortSendRequest counting(uint8_t transaction, int8_t priority)
{
    PortSendRequest request;
    request.transaction = transaction;
    request.object = 0x7123; // A message port (type 7), index 0x123.
    request.priority = priority;
    for (size_t i = 0; i < kPortMessageBytes; ++i) {
        request.message[i] = static_cast<uint8_t>(0xE0 + i);
    }
    return request;
}

// Feeds frames to an assembler as the serving node does.
ContinuedRequestAssembler::Outcome feed(ContinuedRequestAssembler& assembler, const std::vector<uint8_t>& frame)
{
    if (isContinuation(frame.data(), frame.size())) {
        Continuation part;
        EXPECT_EQ(decodeContinuation(frame.data(), frame.size(), part), RemoteMessageError::None);
        return assembler.take(part);
    }
    RemoteRequest first;
    EXPECT_EQ(decodeRequest(frame.data(), frame.size(), first), RemoteMessageError::None);
    EXPECT_EQ(first.service, RemoteService::PortSend);
    return assembler.start(first);
}

} // namespace

TEST(RemoteMessageTest, APortSendIsThreeFramesLaidOutAsTheSpecificationSays)
{
    const Frames frames = portSendFrames(counting(0x5B, -3));
    EXPECT_EQ(frames[0], (std::vector<uint8_t>{11, 0x5B, 0x71, 0x23, 0xFD, 0xE0, 0xE1, 0xE2}));
    EXPECT_EQ(frames[1], (std::vector<uint8_t>{0x9B, 0xE3, 0xE4, 0xE5, 0xE6, 0xE7, 0xE8, 0xE9}));
    EXPECT_EQ(frames[2], (std::vector<uint8_t>{0xAB, 0xEA, 0xEB, 0xEC, 0xED, 0xEE, 0xEF}));
    EXPECT_STREQ(remoteServiceName(RemoteService::PortSend), "port-send");
}

TEST(RemoteMessageTest, APortSendIsPutBackTogetherWhole)
{
    ContinuedRequestAssembler assembler;
    const Frames frames = portSendFrames(counting(0x07, 31));
    EXPECT_EQ(feed(assembler, frames[0]), ContinuedRequestAssembler::Outcome::Started);
    EXPECT_EQ(feed(assembler, frames[1]), ContinuedRequestAssembler::Outcome::Taken);
    EXPECT_EQ(feed(assembler, frames[2]), ContinuedRequestAssembler::Outcome::Complete);
    const PortSendRequest& whole = assembler.portSend();
    EXPECT_EQ(whole.transaction, 0x07);
    EXPECT_EQ(whole.object, 0x7123);
    EXPECT_EQ(whole.priority, 31);
    const PortSendRequest sent = counting(0x07, 31);
    EXPECT_EQ(std::vector<uint8_t>(whole.message, whole.message + kPortMessageBytes),
              std::vector<uint8_t>(sent.message, sent.message + kPortMessageBytes));
}

TEST(RemoteMessageTest, APortSendOutOfTurnOrOfAnotherTransactionIsDroppedNeverMixed)
{
    ContinuedRequestAssembler assembler;
    const Frames a = portSendFrames(counting(0x01, 0));
    const Frames b = portSendFrames(counting(0x02, 0));
    // Part 1 lost: part 2 alone is out of turn.
    (void)feed(assembler, a[0]);
    EXPECT_EQ(feed(assembler, a[2]), ContinuedRequestAssembler::Outcome::Dropped);
    // Another transaction's part 1 after this one's part 0.
    (void)feed(assembler, a[0]);
    EXPECT_EQ(feed(assembler, b[1]), ContinuedRequestAssembler::Outcome::Dropped);
    EXPECT_EQ(feed(assembler, a[1]), ContinuedRequestAssembler::Outcome::Dropped) << "nothing is gathering any more";
    // A continuation with no part 0 at all.
    ContinuedRequestAssembler fresh;
    EXPECT_EQ(feed(fresh, a[1]), ContinuedRequestAssembler::Outcome::Dropped);
}

TEST(RemoteMessageTest, EveryMalformedContinuationIsRefused)
{
    Continuation part;
    const std::vector<uint8_t> partOne{0x91, 1, 2, 3, 4, 5, 6, 7};
    EXPECT_EQ(decodeContinuation(partOne.data(), 7, part), RemoteMessageError::WrongLength);
    const std::vector<uint8_t> partTwo{0xA1, 1, 2, 3, 4, 5, 6, 7};
    EXPECT_EQ(decodeContinuation(partTwo.data(), 8, part), RemoteMessageError::WrongLength);
    for (uint8_t header : {uint8_t{0x81}, uint8_t{0xC1}, uint8_t{0xD1}}) {
        const std::vector<uint8_t> bad{header, 1, 2, 3, 4, 5, 6, 7};
        EXPECT_EQ(decodeContinuation(bad.data(), 8, part), RemoteMessageError::UnknownService)
            << int(header);
    }
    const std::vector<uint8_t> heldPart{0xB1, 0x00, 0x01, 0x10, 0x02, 0, 0, 0};
    EXPECT_EQ(decodeContinuation(heldPart.data(), 7, part), RemoteMessageError::WrongLength);
    for (size_t reserved = 5; reserved < 8; ++reserved) {
        std::vector<uint8_t> bad = heldPart;
        bad[reserved] = 1;
        EXPECT_EQ(decodeContinuation(bad.data(), 8, part), RemoteMessageError::ReservedBits) << reserved;
    }
    EXPECT_FALSE(isContinuation(partOne.data(), 0));
}

TEST(RemoteMessageTest, AHeldAcquireIsTwoFramesLaidOutAsTheSpecificationSays)
{
    HeldAcquireRequest request;
    request.transaction = 0x35;
    request.object = 0xA004;
    request.timeoutMs = 250;
    request.holder = 0x00011002;
    uint8_t frames[kHeldAcquireFrames][kRemoteMessageBytes];
    encodeHeldAcquire(request, frames);
    EXPECT_EQ(std::vector<uint8_t>(frames[0], frames[0] + 8),
              (std::vector<uint8_t>{12, 0x35, 0xA0, 0x04, 0x00, 0x00, 0x00, 0xFA}));
    EXPECT_EQ(std::vector<uint8_t>(frames[1], frames[1] + 8),
              (std::vector<uint8_t>{0xB5, 0x00, 0x01, 0x10, 0x02, 0x00, 0x00, 0x00}));
    EXPECT_STREQ(remoteServiceName(RemoteService::HeldAcquire), "held-acquire");
    EXPECT_STREQ(remoteServiceName(RemoteService::HeldRelease), "held-release");

    ContinuedRequestAssembler assembler;
    RemoteRequest first;
    ASSERT_EQ(decodeRequest(frames[0], 8, first), RemoteMessageError::None);
    EXPECT_EQ(assembler.start(first), ContinuedRequestAssembler::Outcome::Started);
    Continuation part;
    ASSERT_EQ(decodeContinuation(frames[1], 8, part), RemoteMessageError::None);
    EXPECT_EQ(part.part, 3);
    EXPECT_EQ(assembler.take(part), ContinuedRequestAssembler::Outcome::Complete);
    EXPECT_EQ(assembler.service(), RemoteService::HeldAcquire);
    const HeldAcquireRequest whole = assembler.heldAcquire();
    EXPECT_EQ(whole.transaction, 0x35);
    EXPECT_EQ(whole.object, 0xA004);
    EXPECT_EQ(whole.timeoutMs, 250u);
    EXPECT_EQ(whole.holder, 0x00011002u);
}

TEST(RemoteMessageTest, AHeldAcquireAndAPortSendNeverTakeEachOthersParts)
{
    HeldAcquireRequest held;
    held.transaction = 0x02;
    held.object = 0xA001;
    held.holder = 0x00011003;
    uint8_t heldFrames[kHeldAcquireFrames][kRemoteMessageBytes];
    encodeHeldAcquire(held, heldFrames);
    const Frames port = portSendFrames(counting(0x02, 5));

    ContinuedRequestAssembler assembler;
    RemoteRequest first;
    ASSERT_EQ(decodeRequest(heldFrames[0], 8, first), RemoteMessageError::None);
    ASSERT_EQ(assembler.start(first), ContinuedRequestAssembler::Outcome::Started);
    EXPECT_EQ(feed(assembler, port[1]), ContinuedRequestAssembler::Outcome::Dropped)
        << "a port send's part 1 is not a held acquire's part";
    EXPECT_EQ(feed(assembler, port[0]), ContinuedRequestAssembler::Outcome::Started);
    Continuation part;
    ASSERT_EQ(decodeContinuation(heldFrames[1], 8, part), RemoteMessageError::None);
    EXPECT_EQ(assembler.take(part), ContinuedRequestAssembler::Outcome::Dropped)
        << "a held acquire's part is not a port send's";
    // A service of one frame starts nothing.
    RemoteRequest plain;
    plain.service = RemoteService::HeldRelease;
    plain.object = 0xA001;
    EXPECT_EQ(assembler.start(plain), ContinuedRequestAssembler::Outcome::Dropped);
    EXPECT_EQ(assembler.take(part), ContinuedRequestAssembler::Outcome::Dropped);
}

TEST(RemoteMessageTest, ARouteHeaderIsFourBytesLaidOutAsTheSpecificationSays)
{
    RouteHeader header;
    header.hopsLeft = 3;
    header.transaction = 0x5A;
    header.destination = 0x0103;
    uint8_t bytes[kRouteHeaderBytes];
    encodeRouteHeader(header, bytes);
    const uint8_t expected[kRouteHeaderBytes] = {0xC3, 0x5A, 0x01, 0x03};
    EXPECT_EQ(0, std::memcmp(bytes, expected, sizeof bytes));
    ASSERT_TRUE(isRouteHeader(bytes, sizeof bytes));
    RouteHeader back;
    ASSERT_EQ(RemoteMessageError::None, decodeRouteHeader(bytes, sizeof bytes, back));
    EXPECT_EQ(3, back.hopsLeft);
    EXPECT_EQ(0x5A, back.transaction);
    EXPECT_EQ(0x0103, back.destination);
}

TEST(RemoteMessageTest, ARouteHeaderIsNeverARequestOrAContinuation)
{
    // Byte 0's bits 7-6: a service has bit 7 clear, a continuation 10, a header 11.
    for (unsigned service = 1; service <= kLastRemoteService; ++service) {
        const uint8_t first[1] = {static_cast<uint8_t>(service)};
        EXPECT_FALSE(isRouteHeader(first, 1));
    }
    for (uint8_t part = 1; part <= 2; ++part) {
        const uint8_t continuation[1] = {static_cast<uint8_t>(0x80 | part << 4 | 0x0F)};
        EXPECT_FALSE(isRouteHeader(continuation, 1));
    }
    const uint8_t header[kRouteHeaderBytes] = {0xC1, 0x00, 0x00, 0x02};
    RemoteRequest request;
    EXPECT_NE(RemoteMessageError::None, decodeRequest(header, sizeof header, request));
    Continuation part;
    EXPECT_NE(RemoteMessageError::None, decodeContinuation(header, sizeof header, part));
}

TEST(RemoteMessageTest, EveryMalformedRouteHeaderIsRefused)
{
    RouteHeader header;
    const uint8_t tooShort[3] = {0xC1, 0x00, 0x00};
    EXPECT_EQ(RemoteMessageError::WrongLength, decodeRouteHeader(tooShort, sizeof tooShort, header));
    const uint8_t tooLong[5] = {0xC1, 0x00, 0x00, 0x02, 0x00};
    EXPECT_EQ(RemoteMessageError::WrongLength, decodeRouteHeader(tooLong, sizeof tooLong, header));
    const uint8_t noHopLeft[4] = {0xC0, 0x00, 0x00, 0x02};
    EXPECT_EQ(RemoteMessageError::ReservedBits, decodeRouteHeader(noHopLeft, sizeof noHopLeft, header));
    const uint8_t tooManyHops[4] = {static_cast<uint8_t>(0xC0 | (kRouteHops + 1)), 0x00, 0x00, 0x02};
    EXPECT_EQ(RemoteMessageError::ReservedBits, decodeRouteHeader(tooManyHops, sizeof tooManyHops, header));
    const uint8_t reserved[4] = {0xD1, 0x00, 0x00, 0x02};
    EXPECT_EQ(RemoteMessageError::ReservedBits, decodeRouteHeader(reserved, sizeof reserved, header));
    const uint8_t notAHeader[4] = {0x01, 0x00, 0x00, 0x02};
    EXPECT_EQ(RemoteMessageError::ReservedBits, decodeRouteHeader(notAHeader, sizeof notAHeader, header));
}

TEST(RemoteMessageTest, AnAlarmIsThreeFramesLaidOutAsAPortSend)
{
    AlarmRequest request;
    request.transaction = 0x27;
    request.object = 0x3001;
    request.kind = RemoteAlarmKind::Periodic;
    request.value = 8;
    request.owner = 0x00011002;
    request.timeNs = 100'000'000;
    uint8_t frames[kAlarmFrames][kRemoteMessageBytes];
    uint8_t lengths[kAlarmFrames];
    encodeAlarm(request, frames, lengths);
    EXPECT_EQ(lengths[0], 8);
    EXPECT_EQ(lengths[1], 8);
    EXPECT_EQ(lengths[2], 7);
    EXPECT_EQ(std::vector<uint8_t>(frames[0], frames[0] + 8),
              (std::vector<uint8_t>{14, 0x27, 0x30, 0x01, 0x03, 0x00, 0x01, 0x10}));
    EXPECT_EQ(std::vector<uint8_t>(frames[1], frames[1] + 8),
              (std::vector<uint8_t>{0x97, 0x02, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00}));
    EXPECT_EQ(std::vector<uint8_t>(frames[2], frames[2] + 7),
              (std::vector<uint8_t>{0xA7, 0x00, 0x00, 0x05, 0xF5, 0xE1, 0x00}));
    EXPECT_STREQ(remoteServiceName(RemoteService::TimerSetAlarm), "set-alarm");
    EXPECT_STREQ(remoteServiceName(RemoteService::TimerCancelAlarm), "cancel-alarm");

    ContinuedRequestAssembler assembler;
    RemoteRequest first;
    ASSERT_EQ(decodeRequest(frames[0], 8, first), RemoteMessageError::None);
    ASSERT_EQ(assembler.start(first), ContinuedRequestAssembler::Outcome::Started);
    for (size_t part = 1; part < kAlarmFrames; ++part) {
        Continuation continuation;
        ASSERT_EQ(decodeContinuation(frames[part], lengths[part], continuation), RemoteMessageError::None);
        EXPECT_EQ(assembler.take(continuation), part == 2 ? ContinuedRequestAssembler::Outcome::Complete
                                                          : ContinuedRequestAssembler::Outcome::Taken);
    }
    AlarmRequest whole;
    ASSERT_TRUE(assembler.alarm(whole));
    EXPECT_EQ(whole.transaction, 0x27);
    EXPECT_EQ(whole.object, 0x3001);
    EXPECT_EQ(whole.kind, RemoteAlarmKind::Periodic);
    EXPECT_FALSE(whole.signal);
    EXPECT_EQ(whole.value, 8u);
    EXPECT_EQ(whole.owner, 0x00011002u);
    EXPECT_EQ(whole.timeNs, 100'000'000u);
}

TEST(RemoteMessageTest, AnAlarmWhoseFlagsAreNotDefinedIsRefused)
{
    for (uint8_t flags : {uint8_t{0x00}, uint8_t{0x10}, uint8_t{0x04}, uint8_t{0x21}, uint8_t{0x81}}) {
        RemoteRequest first;
        first.service = RemoteService::TimerSetAlarm;
        first.transaction = 0x01;
        first.object = 0x3001;
        first.argument = uint32_t{flags} << 24;
        ContinuedRequestAssembler assembler;
        ASSERT_EQ(assembler.start(first), ContinuedRequestAssembler::Outcome::Started);
        Continuation one;
        one.part = 1;
        one.slot = 1;
        one.count = 7;
        Continuation two = one;
        two.part = 2;
        two.count = 6;
        ASSERT_EQ(assembler.take(one), ContinuedRequestAssembler::Outcome::Taken);
        ASSERT_EQ(assembler.take(two), ContinuedRequestAssembler::Outcome::Complete);
        AlarmRequest alarm;
        EXPECT_FALSE(assembler.alarm(alarm)) << int(flags);
    }
}
