// The configuration protocol's messages (docs/protocols/config.md): what a
// host tool (dcos-config) and a node's system engineering interface agent
// say to each other to find the node, read what it is, and change its
// identity and configuration. A request starts with its command code; its
// reply with the code with the top bit set, then a status byte; a request
// that cannot be read at all is answered [0xFF][status]. Every number is
// little-endian. Pure code, the same on the host and in the node.
#pragma once

#include <sei/SeiStatus.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

constexpr uint8_t kSeiProtocolVersion = 1;
/// The MAC a request carries: the first 16 bytes of HMAC-SHA-256.
constexpr size_t kSeiMacSize = 16;
constexpr size_t kSeiChallengeSize = 16;
/// The node's configuration key (boot::ConfigurationBlock::kConfigurationKeySize).
constexpr size_t kSeiKeySize = 32;
/// The longest text a reply carries (its length is one byte): Identify's
/// version text, GetConfiguration's command line.
constexpr size_t kSeiMaxText = 255;
/// The reply code is the request's with this bit set.
constexpr uint8_t kSeiReplyBit = 0x80;
/// The code of the reply to a request that could not be read at all.
constexpr uint8_t kSeiUnreadableCode = 0xFF;
/// The bits of a serial number, which ProbeSerial compares from the top.
constexpr uint8_t kSeiSerialBits = 32;

/// Identify's flags.
constexpr uint8_t kSeiIdentifyHasKey = 1u << 0;        ///< The node holds a configuration key.
constexpr uint8_t kSeiIdentifyQueriesClosed = 1u << 1; ///< GetConfiguration needs a MAC.
constexpr uint8_t kSeiIdentifyLockedOut = 1u << 2;     ///< Locked out now.
constexpr uint8_t kSeiIdentifySelected = 1u << 3;      ///< The selected node on the broadcast address.
/// GetConfiguration's flags.
constexpr uint8_t kSeiConfigurationQueriesClosed = 1u << 0;

/// Code and status, which every reply starts with.
constexpr size_t kSeiReplyHeaderSize = 2;
/// Identify's reply without its text: node id, CAN node number, board,
/// serial number, protocol, flags, bit rate, configured node id, text length.
constexpr size_t kSeiIdentifyReplyFixedSize = kSeiReplyHeaderSize + 2 + 1 + 1 + 4 + 1 + 1 + 4 + 2 + 1;
/// The largest message: Identify's reply with the longest text.
constexpr size_t kSeiMaxMessage = kSeiIdentifyReplyFixedSize + kSeiMaxText;

enum class SeiCommand : uint8_t {
    Identify = 0x01,         ///< What the node is; never needs a MAC.
    Challenge = 0x02,        ///< A new challenge for the next MAC.
    GetConfiguration = 0x03, ///< The card's configuration; a MAC when the node's queries are closed.
    SetNodeId = 0x10,        ///< Writes the configured node id (MAC).
    SetBitRate = 0x11,       ///< Writes the configured CAN bit rate (MAC).
    Restart = 0x12,          ///< Restarts the node once the reply is sent (MAC).
    ProbeSerial = 0x20,      ///< Scanning: does any node's serial number begin so?
    Select = 0x21,           ///< Scanning: the node with this serial number answers on the broadcast address.
    Deselect = 0x22,         ///< Scanning: no node does any more.
};

/// Whether @p code is a command's request code.
bool isSeiCommand(uint8_t code);

/// Whether a request of @p command carries a MAC always (SetNodeId,
/// SetBitRate, Restart); GetConfiguration's is optional.
bool seiCommandNeedsMac(SeiCommand command);

/// The bits of a serial number ProbeSerial compares: the top @p bits of
/// them (0 to 32).
constexpr uint32_t seiProbeMask(uint8_t bits)
{
    return bits == 0 ? 0 : bits >= kSeiSerialBits ? ~uint32_t{0} : ~uint32_t{0} << (kSeiSerialBits - bits);
}

enum class SeiMessageKind : uint8_t {
    Request = 0,
    Reply = 1,
    Unreadable = 2, ///< [0xFF][status]: the reply to a request that could not be read at all.
};

/// One message, of any command and either direction; the fields its
/// command and kind do not use are ignored.
struct SeiMessage {
    SeiMessageKind kind = SeiMessageKind::Request;
    SeiCommand command = SeiCommand::Identify;
    /// Replies. A reply other than Ok carries nothing more, but LockedOut
    /// its seconds left.
    SeiStatus status = SeiStatus::Ok;
    uint16_t lockoutSecondsLeft = 0;

    /// SetNodeId, SetBitRate, Restart: the MAC, always; GetConfiguration:
    /// when hasMac.
    bool hasMac = false;
    uint8_t mac[kSeiMacSize] = {};

    /// Identify and Select replies: the node id the node runs with;
    /// GetConfiguration reply: the configured one; SetNodeId: the new one.
    uint16_t nodeId = 0;
    /// Identify and Select replies: the CAN node number the node answers as.
    uint8_t canNode = 0;
    /// Identify reply: as in an image header (1: isa486).
    uint8_t board = 0;
    /// Identify reply: the node's; Select: the one to select.
    uint32_t serial = 0;
    /// Identify reply.
    uint8_t protocol = kSeiProtocolVersion;
    /// Identify reply (kSeiIdentify*), GetConfiguration reply (kSeiConfiguration*).
    uint8_t flags = 0;
    /// Identify and GetConfiguration replies: the configured CAN bit rate;
    /// SetBitRate: the new one.
    uint32_t bitRate = 0;
    /// Identify reply: the configured node id.
    uint16_t configuredNodeId = 0;
    /// Identify reply: the version text; GetConfiguration reply: the
    /// command line. Not terminated; into the decoded buffer, and encode
    /// copies from it.
    const char* text = nullptr;
    uint8_t textLength = 0;

    /// Challenge reply.
    uint8_t challenge[kSeiChallengeSize] = {};

    /// GetConfiguration reply: the configuration's; SetNodeId and
    /// SetBitRate replies: the one written.
    uint32_t sequence = 0;
    /// GetConfiguration reply: the lockout after three wrong MACs (0: 60 s).
    uint16_t lockoutSeconds = 0;

    /// ProbeSerial: the node answers when (serial & seiProbeMask(probeBits))
    /// == probeValue and its serial number is not 0.
    uint8_t probeBits = 0;
    uint32_t probeValue = 0;

    /// Writes the message into @p out; its length, or 0 when it does not fit.
    size_t encode(uint8_t* out, size_t capacity) const;
    /// Reads a message of exactly @p length bytes; false for a wrong
    /// length, an unknown code or status, or a field out of its range.
    static bool decode(const uint8_t* data, size_t length, SeiMessage& out);
};

} // namespace sei
