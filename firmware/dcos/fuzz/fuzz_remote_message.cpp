// Fuzz target: the remote transaction messages' decoders
// (docs/protocols/remote-transactions.md), which take every frame a node
// receives as a request or a reply.
//
// Checks: a message the decoder accepts encodes back into exactly the same
// bytes (the layout has no slack, so no two byte strings mean one message),
// and a refused one is refused for a reason the specification gives. The
// input is also taken as a stream of name query parts (8 bytes each), put
// back together as a serving node does: a query it completes has a name of
// 1 to 15 characters, a type with names, and encodes back into its parts.
// Last, as a stream of port send frames (a length byte, then the frame): a
// port send, alarm or held acquire the assembler completes encodes back
// into exactly the frames that made it. A routed request's route header (RemoteMessage.hpp) that
// decodes encodes back into the same four bytes and is never a request.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <dcos/internal/RemoteMessage.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>

using namespace dcos::internal;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    RemoteRequest request;
    const RemoteMessageError requestError = decodeRequest(data, size, request);
    if (requestError == RemoteMessageError::None) {
        uint8_t again[kRemoteMessageBytes];
        encodeRequest(request, again);
        FUZZ_CHECK(size == kRemoteMessageBytes && std::memcmp(again, data, size) == 0);
        FUZZ_CHECK(request.object != 0);
    } else {
        FUZZ_CHECK(requestError == RemoteMessageError::WrongLength ||
                   requestError == RemoteMessageError::UnknownService ||
                   requestError == RemoteMessageError::NullObject);
    }
    RemoteReply reply;
    const RemoteMessageError replyError = decodeReply(data, size, reply);
    if (replyError == RemoteMessageError::None) {
        uint8_t again[kRemoteMessageBytes];
        encodeReply(reply, again);
        FUZZ_CHECK(size == kRemoteMessageBytes && std::memcmp(again, data, size) == 0);
        FUZZ_CHECK(isStatusValue(static_cast<uint8_t>(reply.status)));
    } else {
        FUZZ_CHECK(replyError == RemoteMessageError::WrongLength || replyError == RemoteMessageError::UnknownService ||
                   replyError == RemoteMessageError::UnknownStatus || replyError == RemoteMessageError::ReservedBits);
    }
    NodeStarted announcement;
    const RemoteMessageError announcementError = decodeNodeStarted(data, size, announcement);
    if (announcementError == RemoteMessageError::None) {
        uint8_t again[kRemoteMessageBytes];
        encodeNodeStarted(announcement, again);
        FUZZ_CHECK(size == kRemoteMessageBytes && std::memcmp(again, data, size) == 0);
        FUZZ_CHECK(announcement.node != 0 && announcement.node != 0xFFFF);
    } else {
        FUZZ_CHECK(announcementError == RemoteMessageError::WrongLength ||
                   announcementError == RemoteMessageError::ReservedBits ||
                   announcementError == RemoteMessageError::UnknownNode);
    }
    RouteHeader header;
    const RemoteMessageError headerError = decodeRouteHeader(data, size, header);
    if (headerError == RemoteMessageError::None) {
        uint8_t again[kRouteHeaderBytes];
        encodeRouteHeader(header, again);
        FUZZ_CHECK(size == kRouteHeaderBytes && std::memcmp(again, data, size) == 0);
        FUZZ_CHECK(header.hopsLeft >= 1 && header.hopsLeft <= kRouteHops);
        // A header is neither a request nor a continuation a serving node would take.
        FUZZ_CHECK(requestError != RemoteMessageError::None);
    } else {
        FUZZ_CHECK(headerError == RemoteMessageError::WrongLength || headerError == RemoteMessageError::ReservedBits);
    }
    NameQueryAssembler assembler;
    uint8_t lastParts[kNameQueryFrames][kRemoteMessageBytes]{};
    for (size_t at = 0; at + kRemoteMessageBytes <= size; at += kRemoteMessageBytes) {
        NameQueryPart part;
        const NameQueryError error = decodeNameQueryPart(data + at, kRemoteMessageBytes, part);
        if (error != NameQueryError::None) {
            FUZZ_CHECK(error == NameQueryError::ReservedBits || error == NameQueryError::BadType);
            continue;
        }
        FUZZ_CHECK(part.part < kNameQueryFrames && isNamedObjectType(part.type));
        std::memcpy(lastParts[part.part], data + at, kRemoteMessageBytes);
        if (!assembler.take(part)) {
            continue;
        }
        const size_t length = std::strlen(assembler.name());
        FUZZ_CHECK(length >= 1 && length < kNameQueryNameBytes);
        uint8_t again[kNameQueryFrames][kRemoteMessageBytes];
        encodeNameQuery(assembler.type(), assembler.transaction(), assembler.name(), again, assembler.relays());
        FUZZ_CHECK(std::memcmp(again, lastParts, sizeof again) == 0);
    }
    ContinuedRequestAssembler portSends; // Port sends and held acquires.
    uint8_t made[kPortSendFrames][kRemoteMessageBytes]{};
    uint8_t madeLengths[kPortSendFrames]{};
    for (size_t at = 0; at < size;) {
        const size_t length = data[at++] & 0x0F;
        if (length > size - at) {
            break;
        }
        const uint8_t* frame = data + at;
        at += length;
        if (isContinuation(frame, length)) {
            Continuation part;
            const RemoteMessageError error = decodeContinuation(frame, length, part);
            if (error != RemoteMessageError::None) {
                FUZZ_CHECK(error == RemoteMessageError::WrongLength || error == RemoteMessageError::UnknownService ||
                           error == RemoteMessageError::ReservedBits);
                continue;
            }
            FUZZ_CHECK(part.part >= 1 && part.part <= 3);
            // A held acquire's part (3) goes beside part 0; a port send's in its place.
            const size_t slot = part.part == 3 ? 1 : part.part;
            std::memcpy(made[slot], frame, length);
            madeLengths[slot] = static_cast<uint8_t>(length);
            if (portSends.take(part) != ContinuedRequestAssembler::Outcome::Complete) {
                continue;
            }
            if (portSends.service() == RemoteService::HeldAcquire) {
                // Whole: it encodes back to the very frames it came from.
                FUZZ_CHECK(part.part == 3);
                uint8_t held[kHeldAcquireFrames][kRemoteMessageBytes];
                encodeHeldAcquire(portSends.heldAcquire(), held);
                FUZZ_CHECK(madeLengths[0] == kRemoteMessageBytes && madeLengths[1] == kRemoteMessageBytes);
                FUZZ_CHECK(std::memcmp(held[0], made[0], kRemoteMessageBytes) == 0 &&
                           std::memcmp(held[1], made[1], kRemoteMessageBytes) == 0);
                continue;
            }
            FUZZ_CHECK(part.part == 2);
            if (portSends.service() == RemoteService::TimerSetAlarm) {
                // An alarm with defined flags encodes back to its frames; one
                // without is refused whole.
                AlarmRequest alarm;
                if (!portSends.alarm(alarm)) {
                    FUZZ_CHECK((made[0][4] & 0xEC) != 0 || (made[0][4] & 0x03) == 0);
                    continue;
                }
                uint8_t again[kAlarmFrames][kRemoteMessageBytes];
                uint8_t lengths[kAlarmFrames];
                encodeAlarm(alarm, again, lengths);
                for (size_t i = 0; i < kAlarmFrames; ++i) {
                    FUZZ_CHECK(lengths[i] == madeLengths[i] && std::memcmp(again[i], made[i], lengths[i]) == 0);
                }
                continue;
            }
            uint8_t again[kPortSendFrames][kRemoteMessageBytes];
            uint8_t lengths[kPortSendFrames];
            encodePortSend(portSends.portSend(), again, lengths);
            for (size_t i = 0; i < kPortSendFrames; ++i) {
                FUZZ_CHECK(lengths[i] == madeLengths[i] && std::memcmp(again[i], made[i], lengths[i]) == 0);
            }
            continue;
        }
        RemoteRequest first;
        if (decodeRequest(frame, length, first) == RemoteMessageError::None &&
            (first.service == RemoteService::PortSend || first.service == RemoteService::HeldAcquire ||
             first.service == RemoteService::TimerSetAlarm)) {
            std::memcpy(made[0], frame, length);
            madeLengths[0] = static_cast<uint8_t>(length);
            FUZZ_CHECK(portSends.start(first) == ContinuedRequestAssembler::Outcome::Started);
        }
    }
    return 0;
}
