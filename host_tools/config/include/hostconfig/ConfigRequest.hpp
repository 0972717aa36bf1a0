// The host's half of the configuration protocol's messages
// (docs/protocols/config.md): the requests dcos-config sends, signed where
// they need a MAC, and the replies it takes, read into values that own
// their texts. Pure code on the protocol's own encoder (sei::SeiMessage)
// and MAC (sei::seiMac), so that the tool and the node cannot disagree on
// a byte.
#pragma once

#include <sei/SeiMessage.hpp>
#include <sei/SeiStatus.hpp>

#include <hostimage/ConfigurationKeyFile.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace hostconfig {

using Bytes = std::vector<uint8_t>;
using hostimage::ConfigurationKey;
using Challenge = std::array<uint8_t, sei::kSeiChallengeSize>;

/// An empty request of @p command, its fields to be filled in.
sei::SeiMessage requestOf(sei::SeiCommand command);

/// A request without a MAC (Identify, Challenge, GetConfiguration without
/// one, the scanning commands): its bytes, empty when it does not encode.
Bytes encodeRequest(const sei::SeiMessage& request);

/// A request of @p command with its arguments in @p request (SetNodeId's
/// node id, SetBitRate's rate), signed: its bytes with the MAC last, the
/// MAC computed over every byte before it under @p key and @p challenge
/// for the node @p nodeId with serial number @p serial (as its Identify
/// gave them). Empty when it does not encode.
Bytes signedRequest(sei::SeiMessage request, const ConfigurationKey& key, uint16_t nodeId, uint32_t serial,
                    const Challenge& challenge);

/// Whether @p length bytes at @p data answer a request of @p command: its
/// reply, or the reply to a request the node could not read at all
/// ([0xFF][status]); decoded into @p out (whose text points into @p data).
/// A reply to another command (one left from an earlier exchange, a scan's
/// answer) does not.
bool answers(sei::SeiCommand command, const uint8_t* data, size_t length, sei::SeiMessage& out);

/// What Identify tells of a node.
struct NodeIdentity {
    uint16_t nodeId = 0;           ///< The node id it runs with.
    uint8_t canNode = 0;           ///< The CAN node number it answers as.
    uint8_t board = 0;             ///< As in an image header: 1 isa486.
    uint32_t serial = 0;           ///< 0 for none: such a node cannot be scanned.
    uint8_t protocol = 0;          ///< The configuration protocol it speaks.
    uint8_t flags = 0;             ///< sei::kSeiIdentify*.
    uint32_t bitRate = 0;          ///< The configured CAN bit rate (0: CAN not started at boot).
    uint16_t configuredNodeId = 0; ///< The configured node id (0: the default, 1), from the next start.
    std::string version;           ///< The running firmware's version text.

    bool hasKey() const { return (flags & sei::kSeiIdentifyHasKey) != 0; }
    bool queriesClosed() const { return (flags & sei::kSeiIdentifyQueriesClosed) != 0; }
    bool lockedOut() const { return (flags & sei::kSeiIdentifyLockedOut) != 0; }
    bool selected() const { return (flags & sei::kSeiIdentifySelected) != 0; }

    /// From an Ok Identify reply.
    static NodeIdentity from(const sei::SeiMessage& reply);
};

/// What GetConfiguration tells of a node's card.
struct NodeConfiguration {
    uint32_t sequence = 0;
    uint16_t nodeId = 0;         ///< 0: the kernel's default, 1.
    uint32_t bitRate = 0;        ///< 0: CAN is not started at boot.
    uint8_t flags = 0;           ///< sei::kSeiConfiguration*.
    uint16_t lockoutSeconds = 0; ///< 0: 60 s.
    std::string commandLine;

    bool queriesClosed() const { return (flags & sei::kSeiConfigurationQueriesClosed) != 0; }

    /// From an Ok GetConfiguration reply.
    static NodeConfiguration from(const sei::SeiMessage& reply);
};

/// "isa486", or "board-N" for a number this tool does not know (one word,
/// so that a scan line splits the same way whatever the board).
std::string boardText(uint8_t board);

/// One node's line of `dcos-config scan`, a stable format that scripts may
/// split on white space:
///     serial 4711  node 3  can-node 3  isa486  version 1.0.0  key yes  queries open
std::string scanLine(const NodeIdentity& node);

/// The engineer's sentence for a node's refusal with @p status (and for
/// LockedOut the seconds left), about the node @p who ("node 3").
std::string refusalText(const std::string& who, sei::SeiStatus status, uint16_t lockoutSecondsLeft);

} // namespace hostconfig
