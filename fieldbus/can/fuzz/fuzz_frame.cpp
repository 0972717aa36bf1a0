// Fuzz target: frame validation, the DCOS identifier decoder, the STmin
// encoding, and a frame's round trip through an slcan line.
//
// Each 14-byte record of the input is one candidate frame: a flags byte
// (bit 0 extended, bit 1 remote), a 32-bit identifier, a data length code
// and 8 data bytes. Whatever the values, the checks below must hold.
#include "FuzzCheck.hpp"

#include <can/CanFrame.hpp>
#include <can/IsoTpPci.hpp>
#include <can/MessageIdentifier.hpp>
#include <can/SlcanCodec.hpp>

#include <cstddef>
#include <cstdint>

namespace {

using namespace can;

void checkIdentifier(uint32_t raw)
{
    const LinkResult<MessageIdentifier> decoded = MessageIdentifier::decode(raw);
    const uint8_t type = static_cast<uint8_t>((raw >> MessageIdentifier::kTypeShift) & 0xFF);
    const uint8_t source = static_cast<uint8_t>(raw & 0xFF);
    LinkError expected = LinkError::Ok;
    if (raw > CanFrame::kMaxExtendedId) {
        expected = LinkError::InvalidIdentifier;
    } else if (!isAssignedMessageType(type)) {
        expected = LinkError::UnassignedMessageType;
    } else if (source == MessageIdentifier::kBroadcast && type != static_cast<uint8_t>(MessageType::Configuration)) {
        // Only the configuration protocol's scans and selected node send from 255.
        expected = LinkError::InvalidNodeNumber;
    }
    FUZZ_CHECK(decoded.error() == expected);
    if (!decoded.ok()) {
        return;
    }
    const MessageIdentifier id = decoded.value();
    FUZZ_CHECK(id.encode() == raw);
    FUZZ_CHECK(id.priority() <= MessageIdentifier::kLowestPriority);
    FUZZ_CHECK(id.priority() == MessageIdentifier::priorityOf(raw));
    const LinkResult<MessageIdentifier> again = MessageIdentifier::make(id.priority(), id.type(), id.destination(), id.source());
    FUZZ_CHECK(again.ok() && again.value() == id);
    const LinkResult<MessageIdentifier> answer = id.reversed();
    FUZZ_CHECK(answer.ok() == (!id.isBroadcast() || id.type() == MessageType::Configuration));
    if (answer.ok()) {
        FUZZ_CHECK(answer.value().reversed().ok() && answer.value().reversed().value() == id);
    }
}

void checkSeparationTime(uint8_t code, uint32_t nanoseconds)
{
    const uint32_t decoded = IsoTpPci::separationTimeNs(code);
    FUZZ_CHECK(decoded <= IsoTpPci::kMaxSeparationTimeNs);
    const LinkResult<uint8_t> encoded = IsoTpPci::encodeSeparationTime(nanoseconds);
    FUZZ_CHECK(encoded.ok() == (nanoseconds <= IsoTpPci::kMaxSeparationTimeNs));
    if (encoded.ok()) {
        // Never faster than asked, and the code is one a receiver may send.
        FUZZ_CHECK(IsoTpPci::separationTimeNs(encoded.value()) >= nanoseconds);
        FUZZ_CHECK(encoded.value() <= IsoTpPci::kStMinMaxMilliseconds
                   || (encoded.value() >= IsoTpPci::kStMinFirstMicroseconds
                       && encoded.value() <= IsoTpPci::kStMinLastMicroseconds));
        FUZZ_CHECK(IsoTpPci::encodeSeparationTime(IsoTpPci::separationTimeNs(encoded.value())).value()
                   == encoded.value());
    }
}

void checkFrame(const CanFrame& frame)
{
    FUZZ_CHECK(frame.id() <= CanFrame::maxId(frame.format()));
    FUZZ_CHECK(frame.length() <= CanFrame::kMaxDataLength);
    for (size_t i = frame.isRemote() ? 0 : frame.length(); i < CanFrame::kMaxDataLength; ++i) {
        FUZZ_CHECK(frame.byte(i) == 0);
    }
    const LinkResult<MessageIdentifier> id = MessageIdentifier::fromFrame(frame);
    if (!frame.isExtended()) {
        FUZZ_CHECK(id.error() == LinkError::NotExtendedFrame);
    } else if (frame.isRemote()) {
        FUZZ_CHECK(id.error() == LinkError::UnexpectedRemoteFrame);
    } else {
        FUZZ_CHECK(id.error() == MessageIdentifier::decode(frame.id()).error());
    }
    const LinkResult<PciType> type = IsoTpPci::typeOf(frame);
    FUZZ_CHECK(type.ok() || type.error() == LinkError::ShortFrame || type.error() == LinkError::ReservedPciType);

    // Through an slcan line and back, unchanged.
    SlcanMessage message;
    message.kind = SlcanMessageKind::Frame;
    message.frame = frame;
    char line[SlcanCodec::kMaxLineLength + 1];
    const LinkResult<size_t> written = SlcanCodec::format(message, line, sizeof(line));
    FUZZ_CHECK(written.ok());
    SlcanCodec codec;
    size_t decoded = 0;
    for (size_t i = 0; i < written.value(); ++i) {
        const SlcanCodec::Outcome outcome = codec.feed(static_cast<uint8_t>(line[i]));
        FUZZ_CHECK(outcome != SlcanCodec::Outcome::Rejected);
        if (outcome == SlcanCodec::Outcome::Message) {
            FUZZ_CHECK(i == written.value() - 1);
            FUZZ_CHECK(codec.message().kind == SlcanMessageKind::Frame);
            FUZZ_CHECK(codec.message().frame == frame);
            ++decoded;
        }
    }
    FUZZ_CHECK(decoded == 1);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    fuzz::InputReader input(data, size);
    while (!input.empty()) {
        const uint8_t flags = input.byte();
        const uint32_t id = static_cast<uint32_t>(input.bytes(4));
        const uint8_t length = input.byte();
        uint8_t bytes[8];
        for (uint8_t& byte : bytes) {
            byte = input.byte();
        }
        const IdFormat format = (flags & 1) != 0 ? IdFormat::Extended : IdFormat::Standard;
        const bool remote = (flags & 2) != 0;
        const LinkError expected = CanFrame::check(id, format, length);
        FUZZ_CHECK(expected == (id > CanFrame::maxId(format)      ? LinkError::InvalidIdentifier
                                : length > CanFrame::kMaxDataLength ? LinkError::InvalidDataLength
                                                                    : LinkError::Ok));
        const LinkResult<CanFrame> frame =
            remote ? CanFrame::makeRemote(id, format, length) : CanFrame::makeData(id, format, bytes, length);
        FUZZ_CHECK(frame.error() == expected);
        if (frame.ok()) {
            FUZZ_CHECK(frame.value().id() == id && frame.value().format() == format);
            FUZZ_CHECK(frame.value().isRemote() == remote && frame.value().length() == length);
            for (uint8_t i = 0; i < length && !remote; ++i) {
                FUZZ_CHECK(frame.value().byte(i) == bytes[i]);
            }
            checkFrame(frame.value());
        }
        checkIdentifier(id);
        checkSeparationTime(bytes[0], id);
    }
    return 0;
}
