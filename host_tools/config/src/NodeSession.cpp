#include <hostconfig/NodeSession.hpp>

#include <hostconfig/NodeObjects.hpp>

#include <fmt/core.h>

namespace hostconfig {

int exitCodeOf(const ConfigError& error)
{
    switch (error.kind) {
    case ConfigError::Kind::None: return kExitOk;
    case ConfigError::Kind::Refused:
    case ConfigError::Kind::Unexpected: return kExitRefused;
    case ConfigError::Kind::Silent: return kExitNoAnswer;
    case ConfigError::Kind::Link: return error.link == LinkError::BadArgument ? kExitUsage : kExitNotAvailable;
    }
    return kExitRefused;
}

std::string describe(const ConfigError& error, const std::string& who)
{
    switch (error.kind) {
    case ConfigError::Kind::None: return fmt::format("{}: done", who);
    case ConfigError::Kind::Refused:
        if (error.status == sei::SeiStatus::KernelRefused) {
            return fmt::format("{}'s kernel refused it: {}", who, kernelStatusText(error.kernelStatus));
        }
        return refusalText(who, error.status, error.lockoutSecondsLeft);
    case ConfigError::Kind::Silent: return fmt::format("no answer from {}: {}", who, error.why);
    case ConfigError::Kind::Link: return error.why;
    case ConfigError::Kind::Unexpected: return fmt::format("{}: {}", who, error.why);
    }
    return error.why;
}

Selection::~Selection()
{
    if (active_) {
        if (const ConfigError error = client_.deselect()) {
            warn_(fmt::format("could not send Deselect: {} (the node stays selected until another Select or its "
                              "restart)",
                              error.why));
        }
    }
}

ReachOutcome reachNode(ConfigClient& client, Selection& selection, const NodeAddress& address, NodeIdentity& node,
                       std::string& who)
{
    if (address.bySerial) {
        who = fmt::format("the node with serial {}", address.serial);
        SelectedNode selected;
        selection.begin();
        if (const ConfigError error = client.select(address.serial, selected)) {
            if (error.kind == ConfigError::Kind::Silent) {
                return {kExitNoAnswer, fmt::format("no node with serial {} answered Select (is it on the bus? "
                                                   "`dcos-config scan` lists the serial numbers): {}",
                                                   address.serial, error.why)};
            }
            return {exitCodeOf(error), describe(error, who)};
        }
    } else {
        who = fmt::format("node {}", address.node);
    }
    if (const ConfigError error = client.identify(node)) {
        return {exitCodeOf(error), describe(error, who)};
    }
    if (address.bySerial && node.serial != address.serial) {
        // Another host's Select came in between: do not touch that node.
        return {kExitRefused, fmt::format("the selected node has serial {}, not {}: is another host scanning the bus?",
                                          node.serial, address.serial)};
    }
    who = address.bySerial ? fmt::format("node {} (serial {})", node.nodeId, node.serial)
                           : fmt::format("node {}", node.nodeId);
    return {};
}

} // namespace hostconfig
