#include <hostconfig/ConfigClient.hpp>

#include <fmt/core.h>

#include <algorithm>

namespace hostconfig {

namespace {

using sei::SeiCommand;
using sei::SeiMessage;

ConfigError linkError(LinkError link, const std::string& why)
{
    ConfigError error;
    error.kind = link == LinkError::Silent ? ConfigError::Kind::Silent : ConfigError::Kind::Link;
    error.link = link;
    error.why = why;
    return error;
}

} // namespace

ConfigError ConfigClient::ask(const Bytes& request, SeiCommand command, SeiMessage& out, bool retry)
{
    ConfigError error;
    if (request.empty()) {
        error.kind = ConfigError::Kind::Unexpected;
        error.why = "the request does not encode";
        return error;
    }
    const int attempts = retry ? options_.retries + 1 : 1;
    std::string why;
    for (int attempt = 0; attempt < attempts; ++attempt) {
        if (attempt > 0) {
            ++retransmissions_;
        }
        const LinkError sent = link_.exchange(request, command, reply_, options_.timeout, why);
        if (sent == LinkError::Silent) {
            continue;
        }
        if (sent != LinkError::None) {
            return linkError(sent, why);
        }
        // The link takes only what answers the command; reading it again
        // here keeps that promise from being this class's only guard.
        if (!answers(command, reply_.data(), reply_.size(), out)) {
            error.kind = ConfigError::Kind::Unexpected;
            error.why = "the node's reply does not decode";
            return error;
        }
        if (out.kind == sei::SeiMessageKind::Unreadable || out.status != sei::SeiStatus::Ok) {
            error.kind = ConfigError::Kind::Refused;
            error.status = out.status;
            error.lockoutSecondsLeft = out.lockoutSecondsLeft;
            error.kernelStatus = out.kernelStatus;
        }
        return error;
    }
    error.kind = ConfigError::Kind::Silent;
    error.why = attempts > 1 ? fmt::format("no answer after {} attempts ({})", attempts, why)
                             : fmt::format("no answer ({})", why);
    return error;
}

ConfigError ConfigClient::identify(NodeIdentity& out)
{
    SeiMessage reply;
    const ConfigError error = ask(encodeRequest(requestOf(SeiCommand::Identify)), SeiCommand::Identify, reply);
    if (!error) {
        out = NodeIdentity::from(reply);
    }
    return error;
}

ConfigError ConfigClient::challenge(Challenge& out)
{
    SeiMessage reply;
    const ConfigError error = ask(encodeRequest(requestOf(SeiCommand::Challenge)), SeiCommand::Challenge, reply);
    if (!error) {
        std::copy(std::begin(reply.challenge), std::end(reply.challenge), out.begin());
    }
    return error;
}

ConfigError ConfigClient::select(uint32_t serial, SelectedNode& out)
{
    SeiMessage request = requestOf(SeiCommand::Select);
    request.serial = serial;
    SeiMessage reply;
    const ConfigError error = ask(encodeRequest(request), SeiCommand::Select, reply);
    if (!error) {
        out.nodeId = reply.nodeId;
        out.canNode = reply.canNode;
    }
    return error;
}

ConfigError ConfigClient::deselect()
{
    return announce(encodeRequest(requestOf(SeiCommand::Deselect)));
}

ConfigError ConfigClient::activateBitRate(uint16_t delayMs)
{
    SeiMessage request = requestOf(SeiCommand::ActivateBitRate);
    request.delayMs = delayMs;
    return announce(encodeRequest(request));
}

ConfigError ConfigClient::announce(const Bytes& request)
{
    std::string why;
    const LinkError sent = link_.announce(request, why);
    return sent == LinkError::None ? ConfigError{} : linkError(sent, why);
}

ConfigError ConfigClient::authenticated(const NodeIdentity& node, const ConfigurationKey& key,
                                        const SeiMessage& request, SeiMessage& out, bool once)
{
    ConfigError error;
    // The MAC's layout is the protocol version's: a node of another version
    // would only refuse it, and might count that as a wrong key.
    if (node.protocol != sei::kSeiProtocolVersion) {
        error.kind = ConfigError::Kind::Unexpected;
        error.why = fmt::format("the node speaks configuration protocol {}, this tool {}", node.protocol,
                                sei::kSeiProtocolVersion);
        return error;
    }
    const int attempts = once ? 1 : options_.retries + 1;
    for (int attempt = 0; attempt < attempts; ++attempt) {
        if (attempt > 0) {
            ++retransmissions_;
        }
        Challenge fresh{};
        error = challenge(fresh);
        if (error) {
            return error;
        }
        const Bytes bytes = signedRequest(request, key, node.nodeId, node.serial, fresh);
        // One attempt per challenge: the node uses a challenge up with the
        // first request that carries a MAC, so sending the same bytes again
        // could only be refused (NoChallenge). A lost reply is asked again
        // under a new challenge.
        error = ask(bytes, request.command, out, false);
        if (error.kind != ConfigError::Kind::Silent) {
            return error;
        }
    }
    if (attempts > 1) {
        error.why = fmt::format("no answer after {} attempts, each under a new challenge ({})", attempts, error.why);
    }
    return error;
}

ConfigError ConfigClient::query(const NodeIdentity& node, const ConfigurationKey* key, const SeiMessage& request,
                                SeiMessage& out)
{
    return key != nullptr ? authenticated(node, *key, request, out) : ask(encodeRequest(request), request.command, out);
}

ConfigError ConfigClient::change(const NodeIdentity& node, const ConfigurationKey& key, const SeiMessage& request,
                                 SeiMessage& out, bool once)
{
    return authenticated(node, key, request, out, once);
}

ConfigError ConfigClient::getConfiguration(const NodeIdentity& node, const ConfigurationKey* key,
                                           NodeConfiguration& out)
{
    SeiMessage reply;
    const ConfigError error = query(node, key, requestOf(SeiCommand::GetConfiguration), reply);
    if (!error) {
        out = NodeConfiguration::from(reply);
    }
    return error;
}

ConfigError ConfigClient::setNodeId(const NodeIdentity& node, const ConfigurationKey& key, uint16_t nodeId,
                                    uint32_t& sequence)
{
    SeiMessage request = requestOf(SeiCommand::SetNodeId);
    request.nodeId = nodeId;
    SeiMessage reply;
    const ConfigError error = authenticated(node, key, request, reply);
    if (!error) {
        sequence = reply.sequence;
    }
    return error;
}

ConfigError ConfigClient::setBitRate(const NodeIdentity& node, const ConfigurationKey& key, uint32_t bitRate,
                                     uint32_t& sequence)
{
    SeiMessage request = requestOf(SeiCommand::SetBitRate);
    request.bitRate = bitRate;
    SeiMessage reply;
    const ConfigError error = authenticated(node, key, request, reply);
    if (!error) {
        sequence = reply.sequence;
    }
    return error;
}

ConfigError ConfigClient::restart(const NodeIdentity& node, const ConfigurationKey& key)
{
    SeiMessage reply;
    ConfigError error = authenticated(node, key, requestOf(SeiCommand::Restart), reply, true);
    if (error.kind == ConfigError::Kind::Silent) {
        error.why = fmt::format("no reply to Restart: the node may have taken it and be restarting already, so it "
                                "was not sent again ({})",
                                error.why);
    }
    return error;
}

ConfigError ConfigClient::scan(std::vector<uint32_t>& serials)
{
    ConfigError error;
    SerialSearch search([&](uint8_t bits, uint32_t value) {
        bool answered = false;
        std::string why;
        const LinkError sent = link_.probe(bits, value, answered, why);
        if (sent != LinkError::None) {
            // A probe nobody acknowledged means nobody is on the bus: the
            // search cannot go on either way.
            error = linkError(sent, why);
            return SerialSearch::Answer::Failed;
        }
        return answered ? SerialSearch::Answer::Match : SerialSearch::Answer::Silent;
    });
    const SerialSearch::Outcome outcome = search.run();
    probes_ = search.probes();
    serials = search.serials();
    if (outcome == SerialSearch::Outcome::TooMany) {
        error.kind = ConfigError::Kind::Unexpected;
        error.why = fmt::format("more than {} serial numbers answered: something on the bus answers every probe",
                                SerialSearch::kDefaultMaxSerials);
    }
    return error;
}

} // namespace hostconfig
