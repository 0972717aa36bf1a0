// The flash protocol's messages (docs/protocols/flash.md): what a host
// tool and a node say to each other to put a signed image into the node's
// card, whatever carries them (SerialFramer on a serial line; ISO-TP on
// CAN). A request's first byte is its type, the second a tag the reply
// echoes; every number is little-endian. Pure code, the same on the host
// and in the node.
#pragma once

#include <image/ImageError.hpp>
#include <image/ImageHeader.hpp>
#include <image/ImageVersion.hpp>

#include <stddef.h>
#include <stdint.h>

namespace flash {

constexpr uint8_t kProtocolVersion = 1;
/// The most payload bytes one Data message carries; a multiple of the card's sector.
constexpr size_t kMaxBlock = 1024;
/// The largest message: Data with a full block.
constexpr size_t kMaxMessage = 16 + kMaxBlock;
constexpr size_t kChallengeSize = 32;
constexpr size_t kKeyIdSize = 32;
constexpr size_t kSignatureSize = 64;

enum class MessageType : uint8_t {
    Hello = 0x01,        ///< Who are you? Answered with HelloReply and a fresh challenge.
    Authenticate = 0x02, ///< The challenge signed with a key the node trusts.
    Begin = 0x03,        ///< An image's header: the node checks it and names the slot.
    Data = 0x04,         ///< A block of the payload at an offset.
    End = 0x05,          ///< All sent: the node verifies the slot and marks it pending.
    Restart = 0x06,      ///< Restart the node (into the pending trial, or into recovery).
    HelloReply = 0x81,
    AuthenticateReply = 0x82,
    BeginReply = 0x83,
    DataReply = 0x84,
    EndReply = 0x85,
    RestartReply = 0x86,
    ErrorReply = 0xFF, ///< The answer to a request that does not decode: only a status.
};

enum class FlashStatus : uint8_t {
    Ok = 0,
    NotAuthenticated = 1, ///< Begin, Data, End or Restart before a successful Authenticate.
    AuthenticationFailed = 2, ///< The key is not trusted, or the signature does not verify.
    ImageRefused = 3,     ///< The header (Begin) or the payload (End) is refused; imageError says why.
    OutOfOrder = 4,       ///< A block not at the expected offset and sequence; nextOffset says where.
    BadBlockCrc = 5,      ///< A block whose CRC does not match its bytes.
    CardError = 6,        ///< The card cannot be read or written.
    NoTransfer = 7,       ///< Data or End without a Begin, or End before every byte arrived.
    Malformed = 8,        ///< A request that does not decode.
    Unsupported = 9,      ///< A request this node does not serve here.
    SlotInUse = 10,       ///< Begin: the slot the image would go to holds the image the node runs (a trial not confirmed yet).
};

/// One line for an engineer.
const char* flashStatusText(FlashStatus status);

enum class NodeMode : uint8_t { Application = 0, Recovery = 1 };
enum class RestartTarget : uint8_t { Boot = 0, Recovery = 1 };

/// One message, of any type; the fields its type does not use are ignored.
struct FlashMessage {
    MessageType type = MessageType::Hello;
    uint8_t tag = 0;
    FlashStatus status = FlashStatus::Ok;

    // HelloReply
    uint8_t protocol = kProtocolVersion;
    NodeMode mode = NodeMode::Recovery;
    uint16_t node = 0;
    uint16_t board = 0;
    uint8_t challenge[kChallengeSize] = {};
    uint8_t confirmedSlot = 0xFF;
    uint8_t trial = 0;
    uint8_t trialSlot = 0xFF;
    bool slotHolds[2] = {};
    image::ImageVersion slotVersion[2];
    uint16_t maxBlock = kMaxBlock;
    /// The transfer the node holds (a Begin's, not ended): its slot (0xFF
    /// none), the bytes acknowledged, and the SHA-256 of its image's
    /// header, by which a host knows whether its image is the one to resume.
    uint8_t transferSlot = 0xFF;
    uint32_t transferOffset = 0;
    uint8_t transferDigest[32] = {};

    // Authenticate
    uint8_t keyId[kKeyIdSize] = {};
    uint8_t signature[kSignatureSize] = {};

    // Begin
    uint8_t header[image::ImageHeader::kSize] = {};
    // BeginReply, EndReply
    image::ImageError imageError = image::ImageError::Ok;
    uint8_t slot = 0xFF;
    uint32_t offset = 0; ///< BeginReply: where to resume; Data: the block's; DataReply: the next expected.

    // Data
    uint32_t sequence = 0;
    uint16_t length = 0;
    uint32_t crc = 0;
    const uint8_t* bytes = nullptr; ///< Into the decoded buffer; encode copies from it.

    // Restart
    RestartTarget target = RestartTarget::Boot;

    /// Writes the message into @p out; its length, or 0 when it does not fit
    /// (or a Data message's length exceeds kMaxBlock).
    size_t encode(uint8_t* out, size_t capacity) const;
    /// Reads a message of exactly @p length bytes; false for a wrong length,
    /// an unknown type, or a field out of its range.
    static bool decode(const uint8_t* data, size_t length, FlashMessage& out);
};

/// What the host signs to authenticate: SHA-256 of "DCOS-FLASH-1", the node
/// id (little-endian) and the challenge.
void authenticationDigest(uint16_t node, const uint8_t (&challenge)[kChallengeSize], uint8_t (&digest)[32]);

} // namespace flash
