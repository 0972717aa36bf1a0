// The publication messages' encoder and decoder, reassembly and duplicate
// filter (PublicationMessage.hpp, docs/protocols/publications.md). Pure
// code: no kernel state.
#include <dcos/internal/PublicationMessage.hpp>

namespace dcos::internal {

namespace {

constexpr uint8_t kKindShift = 6;
constexpr uint8_t kTagShift = 4;
constexpr uint8_t kTagMask = 0x3;
constexpr uint8_t kIndexHighMask = 0x0F;
// Where each part's page bytes sit in the frame and in the page.
constexpr uint8_t kFirstPageBytes = 4;
constexpr uint8_t kLaterPageBytes = 6;
constexpr uint8_t kPageOffset[kPublicationFrames] = {0, kFirstPageBytes, kFirstPageBytes + kLaterPageBytes};
static_assert(kFirstPageBytes + 2 * kLaterPageBytes == kDsmPageSize, "three parts carry the whole page");

constexpr uint8_t tagOf(uint32_t sequence) { return static_cast<uint8_t>(sequence & kTagMask); }

void putHeader(uint8_t* at, PublicationPartKind kind, uint8_t tag, uint16_t index)
{
    at[0] = static_cast<uint8_t>((static_cast<uint8_t>(kind) << kKindShift) | (tag << kTagShift) |
                                 ((index >> 8) & kIndexHighMask));
    at[1] = static_cast<uint8_t>(index);
}

} // namespace

const char* publicationMessageErrorName(PublicationMessageError error)
{
    switch (error) {
    case PublicationMessageError::None: return "none";
    case PublicationMessageError::WrongLength: return "wrong length";
    case PublicationMessageError::WrongTag: return "wrong tag";
    }
    return "?";
}

void encodePublication(uint16_t index, uint32_t dataId, const DsmPage& page,
                       uint8_t (&frames)[kPublicationFrames][kPublicationFrameBytes])
{
    const uint16_t sequence = static_cast<uint16_t>(dataId);
    const uint8_t tag = tagOf(sequence);
    for (size_t part = 0; part < kPublicationFrames; ++part) {
        uint8_t* frame = frames[part];
        putHeader(frame, static_cast<PublicationPartKind>(part), tag, index);
        if (part == 0) {
            frame[2] = static_cast<uint8_t>(sequence >> 8);
            frame[3] = static_cast<uint8_t>(sequence);
            __builtin_memcpy(frame + 4, page.bytes, kFirstPageBytes);
        } else {
            __builtin_memcpy(frame + 2, page.bytes + kPageOffset[part], kLaterPageBytes);
        }
    }
}

void encodeWithdrawal(uint16_t index, uint8_t (&frame)[kWithdrawalBytes])
{
    putHeader(frame, PublicationPartKind::Withdrawal, 0, index);
}

PublicationMessageError decodePublicationPart(const uint8_t* bytes, size_t length, PublicationPart& part)
{
    if (length < 2) {
        return PublicationMessageError::WrongLength;
    }
    const auto kind = static_cast<PublicationPartKind>(bytes[0] >> kKindShift);
    const uint8_t tag = (bytes[0] >> kTagShift) & kTagMask;
    const size_t expected = kind == PublicationPartKind::Withdrawal ? kWithdrawalBytes : kPublicationFrameBytes;
    if (length != expected) {
        return PublicationMessageError::WrongLength;
    }
    part = PublicationPart{};
    part.kind = kind;
    part.tag = tag;
    part.index = static_cast<uint16_t>(((bytes[0] & kIndexHighMask) << 8) | bytes[1]);
    switch (kind) {
    case PublicationPartKind::Withdrawal:
        if (tag != 0) {
            return PublicationMessageError::WrongTag;
        }
        break;
    case PublicationPartKind::First:
        part.sequence = static_cast<uint16_t>((bytes[2] << 8) | bytes[3]);
        if (tagOf(part.sequence) != tag) {
            return PublicationMessageError::WrongTag;
        }
        __builtin_memcpy(part.bytes, bytes + 4, kFirstPageBytes);
        part.byteCount = kFirstPageBytes;
        break;
    case PublicationPartKind::Second:
    case PublicationPartKind::Third:
        __builtin_memcpy(part.bytes, bytes + 2, kLaterPageBytes);
        part.byteCount = kLaterPageBytes;
        break;
    }
    return PublicationMessageError::None;
}

PublicationAssembler::Outcome PublicationAssembler::take(const PublicationPart& part)
{
    const auto number = static_cast<uint8_t>(part.kind);
    if (part.kind == PublicationPartKind::First) {
        // A first part always begins afresh; one begun before and not
        // finished is dropped with it (reported as Gathering: the caller
        // counts incomplete publications by the first parts it saw).
        sequence_ = part.sequence;
        __builtin_memcpy(page_.bytes, part.bytes, kFirstPageBytes);
        next_ = 1;
        return Outcome::Gathering;
    }
    if (part.kind == PublicationPartKind::Withdrawal || next_ == 0 || number != next_ ||
        part.tag != tagOf(sequence_)) {
        next_ = 0;
        return Outcome::Dropped;
    }
    __builtin_memcpy(page_.bytes + kPageOffset[number], part.bytes, kLaterPageBytes);
    if (part.kind == PublicationPartKind::Third) {
        next_ = 0;
        return Outcome::Complete;
    }
    next_ = 2;
    return Outcome::Gathering;
}

bool PublicationFilter::take(uint16_t sequence, uint64_t nowNs)
{
    const auto ahead = static_cast<uint16_t>(sequence - last_);
    const bool newer = ahead != 0 && ahead < 0x8000;
    // The same number is never taken twice, however long after: a node that
    // opens a subscription makes the publisher send its latest page again,
    // which the other subscriber nodes have.
    const bool restarted = ahead != 0 && !newer && nowNs - lastTakenNs_ >= kRestartSilenceNs;
    if (haveLast_ && !newer && !restarted) {
        return false;
    }
    haveLast_ = true;
    last_ = sequence;
    lastTakenNs_ = nowNs;
    return true;
}

void encodeRelayHeader(uint16_t node, uint8_t (&bytes)[kRelayHeaderBytes], uint8_t crossedBefore)
{
    bytes[0] = 0xFF;
    bytes[1] = crossedBefore < kRelayCrossings ? crossedBefore : kRelayCrossings - 1;
    bytes[2] = static_cast<uint8_t>(node >> 8);
    bytes[3] = static_cast<uint8_t>(node);
}

bool decodeRelayHeader(const uint8_t* bytes, size_t length, uint16_t& node, uint8_t* crossedBefore)
{
    if (length != kRelayHeaderBytes || bytes[0] != 0xFF || bytes[1] >= kRelayCrossings) {
        return false;
    }
    node = static_cast<uint16_t>((bytes[2] << 8) | bytes[3]);
    if (crossedBefore != nullptr) {
        *crossedBefore = bytes[1];
    }
    return true;
}

} // namespace dcos::internal
