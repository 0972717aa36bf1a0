// dcos-config's conversation with one node, whatever carries it
// (ConfigLink): each command of the configuration protocol as a call that
// asks again on silence, checks the reply, and says why when it fails,
// and the authenticated commands as the protocol wants them: a fresh
// challenge, the MAC over the request under the node's key, then the
// command. Errors are values; nothing throws.
#pragma once

#include <hostconfig/ConfigLink.hpp>
#include <hostconfig/ConfigRequest.hpp>
#include <hostconfig/SerialSearch.hpp>

#include <sei/SeiStatus.hpp>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace hostconfig {

/// Why a call failed.
struct ConfigError {
    enum class Kind {
        None,
        Refused,    ///< The node answered with a status other than Ok (`status`; `lockoutSecondsLeft` for LockedOut).
        Silent,     ///< No answer after every attempt, or nobody acknowledged.
        Link,       ///< The interface failed (`link` says how).
        Unexpected, ///< An answer that cannot be right: another node's, another protocol version.
    };
    Kind kind = Kind::None;
    sei::SeiStatus status = sei::SeiStatus::Ok;
    uint16_t lockoutSecondsLeft = 0;
    /// For KernelRefused: the node kernel's dcos::Status.
    uint8_t kernelStatus = 0;
    LinkError link = LinkError::None;
    std::string why; ///< For Silent, Link and Unexpected: what happened, in words.

    explicit operator bool() const { return kind != Kind::None; }
};

struct ClientOptions {
    std::chrono::milliseconds timeout{2000}; ///< How long to wait for each reply.
    int retries = 3;                         ///< How often to ask again on silence.
};

/// A Select's answer: who the selected node is.
struct SelectedNode {
    uint16_t nodeId = 0;
    uint8_t canNode = 0;
};

class ConfigClient {
public:
    ConfigClient(ConfigLink& link, const ClientOptions& options) : link_(link), options_(options) {}

    ConfigError identify(NodeIdentity& out);
    ConfigError challenge(Challenge& out);

    /// Makes the node with serial number @p serial the selected node on the
    /// broadcast address (the link must be on it); Silent when no node has it.
    ConfigError select(uint32_t serial, SelectedNode& out);
    /// No node is selected any more.
    ConfigError deselect();
    /// Every node on the bus switches its CAN controller to its configured
    /// bit rate @p delayMs after this (ActivateBitRate; none answers).
    ConfigError activateBitRate(uint16_t delayMs);

    /// The card's configuration of @p node (as its Identify gave it): with a
    /// MAC when @p key is given (checked by the node whether or not its
    /// queries are closed), else without.
    ConfigError getConfiguration(const NodeIdentity& node, const ConfigurationKey* key, NodeConfiguration& out);

    /// SetNodeId and SetBitRate: the configuration sequence written in @p sequence.
    ConfigError setNodeId(const NodeIdentity& node, const ConfigurationKey& key, uint16_t nodeId, uint32_t& sequence);
    ConfigError setBitRate(const NodeIdentity& node, const ConfigurationKey& key, uint32_t bitRate,
                           uint32_t& sequence);
    /// Restart: never sent twice, since a node that took the first and lost
    /// its reply is already restarting; silence after it is said as such.
    ConfigError restart(const NodeIdentity& node, const ConfigurationKey& key);

    /// Any query (sei::seiCommandIsQuery): with a MAC when @p key is given
    /// (the node checks it whether or not its queries are closed), else
    /// without; asked again on silence. @p out's names and text point into
    /// this client's last reply: valid until its next call.
    ConfigError query(const NodeIdentity& node, const ConfigurationKey* key, const sei::SeiMessage& request,
                      sei::SeiMessage& out);
    /// Any command that changes something, authenticated under a fresh
    /// challenge. With @p once it is not asked again on silence: a create
    /// whose reply was lost may have been done, and doing it twice is not
    /// the same (the caller says so and lets the user look first).
    ConfigError change(const NodeIdentity& node, const ConfigurationKey& key, const sei::SeiMessage& request,
                       sei::SeiMessage& out, bool once);

    /// Every serial number on the bus (SerialSearch, with the link's probes).
    ConfigError scan(std::vector<uint32_t>& serials);

    /// Requests sent again on silence, over all calls.
    unsigned retransmissions() const { return retransmissions_; }
    /// The probes of the last scan.
    unsigned probes() const { return probes_; }

private:
    /// Sends @p request (of @p command) up to 1 + retries times while the
    /// link is silent (once when not @p retry); the reply, checked to be Ok,
    /// is left in reply_ and @p out.
    ConfigError ask(const Bytes& request, sei::SeiCommand command, sei::SeiMessage& out, bool retry = true);
    /// A fresh challenge, then @p request signed under it; both again on
    /// silence, as a lost reply used the challenge up (unless @p once).
    ConfigError announce(const Bytes& request);
    ConfigError authenticated(const NodeIdentity& node, const ConfigurationKey& key, const sei::SeiMessage& request,
                              sei::SeiMessage& out, bool once = false);

    ConfigLink& link_;
    ClientOptions options_;
    /// The last reply's bytes: a decoded message's text points into them.
    Bytes reply_;
    unsigned retransmissions_ = 0;
    unsigned probes_ = 0;
};

} // namespace hostconfig
