#include <hostconfig/ConfigRequest.hpp>

#include <sei/SeiAuthenticator.hpp>

#include <image/ImageHeader.hpp>

#include <fmt/core.h>
#include <mbedtls/platform_util.h>

#include <algorithm>

namespace hostconfig {

sei::SeiMessage requestOf(sei::SeiCommand command)
{
    sei::SeiMessage message;
    message.kind = sei::SeiMessageKind::Request;
    message.command = command;
    return message;
}

Bytes encodeRequest(const sei::SeiMessage& request)
{
    sei::SeiMessage message = request;
    message.kind = sei::SeiMessageKind::Request;
    Bytes bytes(sei::kSeiMaxMessage);
    bytes.resize(message.encode(bytes.data(), bytes.size()));
    return bytes;
}

Bytes signedRequest(sei::SeiMessage request, const ConfigurationKey& key, uint16_t nodeId, uint32_t serial,
                    const Challenge& challenge)
{
    request.hasMac = true;
    std::fill(std::begin(request.mac), std::end(request.mac), uint8_t{0});
    Bytes bytes = encodeRequest(request);
    if (bytes.size() < sei::kSeiMacSize) {
        return {};
    }
    // seiMac takes arrays, as the node holds them; the copy of the key is
    // wiped so that it does not linger on the stack.
    uint8_t keyBytes[sei::kSeiKeySize];
    std::copy(key.begin(), key.end(), keyBytes);
    uint8_t challengeBytes[sei::kSeiChallengeSize];
    std::copy(challenge.begin(), challenge.end(), challengeBytes);
    uint8_t mac[sei::kSeiMacSize];
    const size_t covered = bytes.size() - sei::kSeiMacSize;
    sei::seiMac(keyBytes, nodeId, serial, challengeBytes, bytes.data(), covered, mac);
    mbedtls_platform_zeroize(keyBytes, sizeof keyBytes);
    std::copy(std::begin(mac), std::end(mac), bytes.begin() + static_cast<std::ptrdiff_t>(covered));
    return bytes;
}

bool answers(sei::SeiCommand command, const uint8_t* data, size_t length, sei::SeiMessage& out)
{
    sei::SeiMessage reply;
    if (!sei::SeiMessage::decode(data, length, reply)) {
        return false;
    }
    if (reply.kind == sei::SeiMessageKind::Unreadable ||
        (reply.kind == sei::SeiMessageKind::Reply && reply.command == command)) {
        out = reply;
        return true;
    }
    return false;
}

NodeIdentity NodeIdentity::from(const sei::SeiMessage& reply)
{
    NodeIdentity node;
    node.nodeId = reply.nodeId;
    node.canNode = reply.canNode;
    node.board = reply.board;
    node.serial = reply.serial;
    node.protocol = reply.protocol;
    node.flags = reply.flags;
    node.bitRate = reply.bitRate;
    node.configuredNodeId = reply.configuredNodeId;
    if (reply.text != nullptr) {
        node.version.assign(reply.text, reply.textLength);
    }
    return node;
}

NodeConfiguration NodeConfiguration::from(const sei::SeiMessage& reply)
{
    NodeConfiguration configuration;
    configuration.sequence = reply.sequence;
    configuration.nodeId = reply.nodeId;
    configuration.bitRate = reply.bitRate;
    configuration.flags = reply.flags;
    configuration.lockoutSeconds = reply.lockoutSeconds;
    if (reply.text != nullptr) {
        configuration.commandLine.assign(reply.text, reply.textLength);
    }
    return configuration;
}

std::string boardText(uint8_t board)
{
    const char* name = image::boardName(static_cast<image::BoardType>(board));
    return name != nullptr ? std::string(name) : fmt::format("board-{}", board);
}

std::string scanLine(const NodeIdentity& node)
{
    // The version text comes from the node: white space in it would shift
    // the fields a script splits on, so it becomes underscores.
    std::string version = node.version.empty() ? std::string("-") : node.version;
    std::replace_if(version.begin(), version.end(), [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }, '_');
    return fmt::format("serial {}  node {}  can-node {}  {}  version {}  key {}  queries {}", node.serial, node.nodeId,
                       node.canNode, boardText(node.board), version, node.hasKey() ? "yes" : "no",
                       node.queriesClosed() ? "closed" : "open");
}

std::string refusalText(const std::string& who, sei::SeiStatus status, uint16_t lockoutSecondsLeft)
{
    switch (status) {
    case sei::SeiStatus::Ok: return fmt::format("{}: done", who);
    case sei::SeiStatus::Malformed:
    case sei::SeiStatus::UnknownCommand:
        return fmt::format("{} did not understand the request ({}): does it speak configuration protocol {}?", who,
                           sei::seiStatusText(status), sei::kSeiProtocolVersion);
    case sei::SeiStatus::NoChallenge:
        return fmt::format("{} had no challenge outstanding for the request (did another host ask it for one in "
                           "between?): try again",
                           who);
    case sei::SeiStatus::StaleChallenge:
        return fmt::format("{} found its challenge older than 30 s: try again", who);
    case sei::SeiStatus::BadMac:
        return fmt::format("{} refused the key: it is not this node's configuration key (three wrong keys in a row "
                           "lock the node out)",
                           who);
    case sei::SeiStatus::LockedOut:
        return fmt::format("{} is locked out for {} s after three wrong keys", who, lockoutSecondsLeft);
    case sei::SeiStatus::NoKey:
        return fmt::format("{} holds no configuration key: it was made without dcos-card create --config-key", who);
    case sei::SeiStatus::InvalidArgument:
        return fmt::format("{} cannot take the value: node ids are 1 to 254, and a bit rate must be one its CAN "
                           "controller makes exactly",
                           who);
    case sei::SeiStatus::CardError:
        return fmt::format("{} could not read or write its card; nothing changed", who);
    case sei::SeiStatus::NotPermitted:
        return fmt::format("{} has closed queries: give its configuration key with -K to read its configuration",
                           who);
    case sei::SeiStatus::KernelRefused:
        return fmt::format("{}'s kernel refused it", who);
    }
    return fmt::format("{} answered with an unknown status {}", who, static_cast<unsigned>(status));
}

} // namespace hostconfig
