// The system messages of publications over the network (seed 7.10, Fig.
// 7.12): how a publisher's Write reaches the subscribers of other nodes.
// docs/protocols/publications.md is the specification; this is its only
// encoder and decoder, with the receiver's reassembly and duplicate filter,
// pure code shared by the kernel, the host tests and the fuzz target.
//
// A publication is a 16-byte page and a sequence number, sent to the
// broadcast address in three frames of eight bytes (message type 0x20 of
// docs/protocols/can.md); a withdrawal, sent when the publisher is deleted,
// is one frame of two bytes. Every frame begins with the same header, so a
// receiver knows from any one of them which publisher it is about:
//
//     byte 0   bits 7-6 part (0, 1, 2: the page's parts; 3: withdrawal)
//              bits 5-4 tag: the sequence number's low two bits (0 in a withdrawal)
//              bits 3-0 the publisher id's bits 11-8
//     byte 1   the publisher id's bits 7-0
//     part 0   bytes 2-3 sequence number (big-endian), bytes 4-7 page bytes 0-3
//     part 1   bytes 2-7 page bytes 4-9
//     part 2   bytes 2-7 page bytes 10-15
//
// The id's other bits, its node and type, are not sent: the node is the
// sender's, found from its physical address by the network interfaces
// manager's reverse mapping, and the type is always DsmPublisher.
//
// The sequence number is the low 16 bits of the publisher's data
// identifier. A node sends the three parts of one publication in a row, at
// one priority, and a CAN controller keeps frames of one identifier in
// order, so the parts arrive in order on each bus; the tag catches the rare
// case of two publications interleaved (an interrupt handler's Write in the
// middle of the owner's), and the receiver then drops the torn one.
#pragma once

#include <dcos/DsmAgent.hpp>
#include <dcos/ObjectId.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// Frames of one publication.
constexpr size_t kPublicationFrames = 3;
/// Bytes of each frame of a publication, and of a withdrawal.
constexpr size_t kPublicationFrameBytes = 8;
constexpr size_t kWithdrawalBytes = 2;

// ---- relayed publications (docs/protocols/publications.md, "Across a gateway")
//
// A gateway passes a publisher's frames from the publisher's bus to another,
// message type 0x21 (RelayedPublication), each frame right after a relay
// header that names the publisher's node:
//
//     relay header   byte 0 0xFF, byte 1 the gateways the frame crossed
//                    before this one (0 to kRelayCrossings - 1), bytes 2-3
//                    the logical node
//
// A receiver takes the frame that follows a header from the same sender as
// that node's, and drops a frame that follows none: without its node the
// publisher's index names nothing. A gateway that relays a relayed frame
// further counts one more crossing; a frame that crossed kRelayCrossings
// gateways goes no further, so relays set up in a circle end.

/// Bytes of a relay header.
constexpr size_t kRelayHeaderBytes = 4;
/// The most gateways a publication frame crosses: as many as a routed
/// request's hops (RemoteMessage.hpp's kRouteHops).
constexpr uint8_t kRelayCrossings = 4;

/// The relay header naming @p node, for a frame that crossed @p crossedBefore gateways before this one.
void encodeRelayHeader(uint16_t node, uint8_t (&bytes)[kRelayHeaderBytes], uint8_t crossedBefore = 0);
/// Whether a relayed frame of @p length bytes is a relay header; the node
/// into @p node and, when not null, the crossings before into @p crossedBefore.
bool decodeRelayHeader(const uint8_t* bytes, size_t length, uint16_t& node, uint8_t* crossedBefore = nullptr);

/// What a frame is.
enum class PublicationPartKind : uint8_t {
    First = 0,      ///< Sequence number and page bytes 0-3.
    Second = 1,     ///< Page bytes 4-9.
    Third = 2,      ///< Page bytes 10-15: the publication is complete.
    Withdrawal = 3, ///< The publisher was deleted.
};

/// One decoded frame.
struct PublicationPart {
    PublicationPartKind kind = PublicationPartKind::First;
    uint8_t tag = 0;       ///< The sequence number's low two bits.
    uint16_t index = 0;    ///< The publisher id's low 12 bits (type and node are not sent).
    uint16_t sequence = 0; ///< First part only.
    uint8_t bytes[6]{};    ///< The page bytes this part carries.
    uint8_t byteCount = 0;
};

/// Why a frame was refused; each is counted by the receiver.
enum class PublicationMessageError : uint8_t {
    None,
    WrongLength, ///< Not eight bytes (two for a withdrawal).
    WrongTag,    ///< A first part whose tag is not its sequence number's, or a withdrawal with a tag.
};

const char* publicationMessageErrorName(PublicationMessageError error);

/// The publisher id's bits a frame carries.
constexpr uint16_t publicationIndexOf(ObjectId publisher) { return static_cast<uint16_t>(publisher.raw() & 0x0FFF); }
/// The id of the publisher with @p index on node @p node.
constexpr ObjectId publisherOn(uint16_t node, uint16_t index)
{
    return ObjectId(node, ObjectType::DsmPublisher, index);
}

/// The three frames of a publication of @p page with data identifier @p dataId.
void encodePublication(uint16_t index, uint32_t dataId, const DsmPage& page,
                       uint8_t (&frames)[kPublicationFrames][kPublicationFrameBytes]);
/// The frame that withdraws publisher @p index.
void encodeWithdrawal(uint16_t index, uint8_t (&frame)[kWithdrawalBytes]);

/// Decodes one frame of @p length bytes; None and @p part filled in, or why not.
PublicationMessageError decodePublicationPart(const uint8_t* bytes, size_t length, PublicationPart& part);

/// Puts one publisher's parts from one bus back together. A part out of
/// turn, or with another tag, drops what was gathered: the receiver never
/// makes a page of two publications.
class PublicationAssembler {
public:
    enum class Outcome : uint8_t {
        Gathering, ///< Taken; more parts to come.
        Complete,  ///< The third part: sequence() and page() hold the publication.
        Dropped,   ///< Out of turn: what was gathered, and this part, are dropped.
    };

    /// Takes a part of kind First, Second or Third.
    Outcome take(const PublicationPart& part);

    uint16_t sequence() const { return sequence_; }
    const DsmPage& page() const { return page_; }

    /// Forgets a publication begun.
    void reset() { next_ = 0; }

private:
    uint8_t next_ = 0; // The part expected: 1 or 2 while gathering, 0 otherwise.
    uint16_t sequence_ = 0;
    DsmPage page_{};
};

/// Decides whether a complete publication is news for a subscriber node,
/// which receives each publication once per bus. Sequence numbers are
/// compared as serial numbers (RFC 1982): one ahead of the last taken by
/// 1 to 32767 is newer and taken; the same one, or one a little behind
/// (a copy from a slower bus), is a duplicate. A number behind the last one
/// after a silence of kRestartSilenceNs is taken too: the publisher's node
/// restarted and counts from 1 again, or both buses were down for a while.
/// The same number is never taken twice.
class PublicationFilter {
public:
    /// A bus delivers a copy of a publication within a few frame times of
    /// the other (its transmit queue holds 16 frames); a node restarts in
    /// seconds. A second separates the two by far.
    static constexpr uint64_t kRestartSilenceNs = 1'000'000'000;

    /// Whether the publication with @p sequence, complete at @p nowNs, is taken.
    bool take(uint16_t sequence, uint64_t nowNs);

    void reset() { haveLast_ = false; }

private:
    bool haveLast_ = false;
    uint16_t last_ = 0;
    uint64_t lastTakenNs_ = 0;
};

} // namespace dcos::internal
