// What every host tool that talks to one node over the configuration
// protocol does the same way (dcos-config, dcos-mon): reach the node by its
// CAN node number or, selected on the broadcast address, by its serial
// number; identify it; deselect it whichever way the tool ends; and turn a
// failure into the exit status and the sentence the tools document (0 done,
// 1 refused by the node, 2 bad arguments, 3 interface or file, 4 no answer).
#pragma once

#include <hostconfig/ConfigClient.hpp>
#include <hostconfig/ConfigRequest.hpp>

#include <cstdint>
#include <functional>
#include <string>

namespace hostconfig {

constexpr int kExitOk = 0;
constexpr int kExitRefused = 1;
constexpr int kExitUsage = 2;
constexpr int kExitNotAvailable = 3;
constexpr int kExitNoAnswer = 4;

/// The exit status of a tool that failed with @p error.
int exitCodeOf(const ConfigError& error);

/// The engineer's sentence for @p error about @p who ("node 3"); a kernel's
/// refusal is said in the kernel's words.
std::string describe(const ConfigError& error, const std::string& who);

/// A node reached by its serial number stays selected on the broadcast
/// address until this ends, whichever way the tool ends: a selection left
/// behind would make that node take every later request to the broadcast
/// address, another host's too. A Deselect that cannot be sent is told to
/// @p warn.
class Selection {
public:
    Selection(ConfigClient& client, std::function<void(const std::string&)> warn)
        : client_(client), warn_(std::move(warn))
    {
    }
    ~Selection();
    Selection(const Selection&) = delete;
    Selection& operator=(const Selection&) = delete;

    void begin() { active_ = true; }

private:
    ConfigClient& client_;
    std::function<void(const std::string&)> warn_;
    bool active_ = false;
};

/// Which node a tool was told to reach.
struct NodeAddress {
    bool bySerial = false;
    uint32_t serial = 0;
    int node = -1; ///< The CAN node number, when not by serial.
};

/// How reaching a node ended: kExitOk, or the exit status and what to say.
struct ReachOutcome {
    int code = kExitOk;
    std::string message;
};

/// Selects the node (by serial number) and identifies it: @p node, and the
/// name messages give it in @p who ("node 5 (serial 1001)").
ReachOutcome reachNode(ConfigClient& client, Selection& selection, const NodeAddress& address, NodeIdentity& node,
                       std::string& who);

} // namespace hostconfig
