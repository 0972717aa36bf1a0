// dcos-config: find the controllers on a CAN bus, read what they are, and
// change their node id and CAN bit rate (docs/protocols/config.md).
//
//     dcos-config keygen -o FILE [--force]
//     dcos-config -i IFACE scan
//     dcos-config -i IFACE info (-n NODE | --serial S) [-K KEYFILE]
//     dcos-config -i IFACE set-node (-n NODE | --serial S) -K KEYFILE NEWID
//     dcos-config -i IFACE set-bitrate (-n NODE | --serial S) -K KEYFILE RATE
//     dcos-config -i IFACE restart (-n NODE | --serial S) -K KEYFILE
//
// IFACE is a CAN interface as every DCOS tool takes it (can0,
// slcan:/dev/ttyACM0, lab:/hub.sock:can0). A node is reached at its CAN
// node number (-n), or by its serial number (--serial): the tool selects
// it on the broadcast address, which tells apart nodes that share a CAN
// node number (two fresh controllers with the default node id), talks to
// it there and deselects it at the end. `scan` finds every serial number
// on the bus by ProbeSerial's binary search and identifies each node; a
// node whose card carries no serial number (0) takes no part in a scan
// and can only be reached with -n. The changes need the node's
// configuration key (KEYFILE, made by `keygen` and given to `dcos-card
// create --config-key` at manufacture): each is signed under a fresh
// challenge of the node. A node id or bit rate written takes effect when
// the node next starts (`restart`).
//
// Every command takes --json. Exit status: 0 done; 1 refused by the node
// (its status: a wrong key, a lockout, no key, a value it cannot take) or
// an answer that cannot be right; 2 bad arguments (also -K missing for a
// node whose queries are closed); 3 the interface or a file is not
// available (or failed); 4 no answer: the node was silent, or nobody
// acknowledged the frames.
#include <hostconfig/CanConfigLink.hpp>
#include <hostconfig/ConfigClient.hpp>
#include <hostconfig/ConfigRequest.hpp>

#include <hostimage/ConfigurationKeyFile.hpp>

#include <can/MessageIdentifier.hpp>
#include <sei/CanSeiServer.hpp>
#include <sei/SeiAuthenticator.hpp>
#include <sei/SeiMessage.hpp>

#include <dcos/Version.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace {

using hostconfig::ConfigClient;
using hostconfig::ConfigError;
using hostconfig::ConfigurationKey;
using hostconfig::LinkError;
using hostconfig::NodeConfiguration;
using hostconfig::NodeIdentity;

constexpr int kExitOk = 0;
constexpr int kExitRefused = 1;
constexpr int kExitUsage = 2;
constexpr int kExitNotAvailable = 3;
constexpr int kExitNoAnswer = 4;

int fail(int code, const std::string& message)
{
    fmt::print(stderr, "dcos-config: {}\n", message);
    return code;
}

void warn(const std::string& message) { fmt::print(stderr, "dcos-config: {}\n", message); }

struct Options {
    std::string interface;
    int source = sei::kCanSeiHostNode;
    int priority = sei::kCanSeiPriority;
    bool kernelIsoTp = false;
    long timeoutMs = 2000;
    int retries = 3;
    long probeMs = static_cast<long>(sei::kCanSeiProbeWaitNs / 1000000);
    bool json = false;
    int node = -1;
    uint32_t serial = 0;
    bool bySerial = false;
    std::string keyFile;
    std::string output;
    bool force = false;
    uint16_t newNodeId = 0;
    uint32_t bitRate = 0;
};

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

// The engineer's sentence for @p error about @p who ("node 3").
std::string describe(const ConfigError& error, const std::string& who)
{
    switch (error.kind) {
    case ConfigError::Kind::None: return fmt::format("{}: done", who);
    case ConfigError::Kind::Refused: return hostconfig::refusalText(who, error.status, error.lockoutSecondsLeft);
    case ConfigError::Kind::Silent: return fmt::format("no answer from {}: {}", who, error.why);
    case ConfigError::Kind::Link: return error.why;
    case ConfigError::Kind::Unexpected: return fmt::format("{}: {}", who, error.why);
    }
    return error.why;
}

int failWith(const ConfigError& error, const std::string& who) { return fail(exitCodeOf(error), describe(error, who)); }

nlohmann::json identityJson(const NodeIdentity& node)
{
    return {{"serial", node.serial},
            {"node", node.nodeId},
            {"can_node", node.canNode},
            {"board", hostconfig::boardText(node.board)},
            {"version", node.version},
            {"protocol", node.protocol},
            {"key", node.hasKey()},
            {"queries", node.queriesClosed() ? "closed" : "open"},
            {"locked_out", node.lockedOut()},
            {"selected", node.selected()},
            {"configured_node", node.configuredNodeId},
            {"configured_bit_rate", node.bitRate}};
}

nlohmann::json configurationJson(const NodeConfiguration& configuration)
{
    return {{"sequence", configuration.sequence},
            {"node", configuration.nodeId},
            {"bit_rate", configuration.bitRate},
            {"queries", configuration.queriesClosed() ? "closed" : "open"},
            {"lockout_seconds", configuration.lockoutSeconds},
            {"command_line", configuration.commandLine}};
}

std::string nodeIdText(uint16_t nodeId)
{
    return nodeId == 0 ? std::string("0 (the kernel's default, 1)") : std::to_string(nodeId);
}

std::string bitRateText(uint32_t bitRate)
{
    return bitRate == 0 ? std::string("0 (CAN is not started at boot)") : fmt::format("{} bit/s", bitRate);
}

std::optional<ConfigurationKey> readKey(const Options& options, int& code)
{
    std::string error;
    bool unreadable = false;
    std::optional<ConfigurationKey> key = hostimage::readConfigurationKey(options.keyFile, error, unreadable);
    if (!key) {
        code = fail(kExitNotAvailable, error);
    }
    return key;
}

// A node reached by its serial number stays selected on the broadcast
// address until this ends, whichever way the command ends: a selection left
// behind would make that node take every later request to the broadcast
// address, another host's too.
class Selection {
public:
    explicit Selection(ConfigClient& client) : client_(client) {}
    ~Selection()
    {
        if (active_) {
            if (const ConfigError error = client_.deselect()) {
                warn(fmt::format("could not send Deselect: {} (the node stays selected until another Select or its "
                                 "restart)",
                                 error.why));
            }
        }
    }
    Selection(const Selection&) = delete;
    Selection& operator=(const Selection&) = delete;

    void begin() { active_ = true; }

private:
    ConfigClient& client_;
    bool active_ = false;
};

std::unique_ptr<hostconfig::CanConfigLink> openLink(const Options& options, uint8_t node, int& code)
{
    hostconfig::CanConfigAddress address;
    address.node = node;
    address.host = static_cast<uint8_t>(options.source);
    address.priority = static_cast<uint8_t>(options.priority);
    address.kernelIsoTp = options.kernelIsoTp;
    address.probeWait = std::chrono::milliseconds(options.probeMs);
    LinkError error = LinkError::None;
    std::string why;
    std::unique_ptr<hostconfig::CanConfigLink> link = hostconfig::CanConfigLink::open(options.interface, address, error, why);
    if (!link) {
        code = fail(error == LinkError::BadArgument ? kExitUsage : kExitNotAvailable, why);
    }
    return link;
}

// Reaches the node -n or --serial names and identifies it: @p node and the
// name messages give it (@p who), or the exit code.
int reach(ConfigClient& client, Selection& selection, const Options& options, NodeIdentity& node, std::string& who)
{
    if (options.bySerial) {
        who = fmt::format("the node with serial {}", options.serial);
        hostconfig::SelectedNode selected;
        selection.begin();
        if (const ConfigError error = client.select(options.serial, selected)) {
            if (error.kind == ConfigError::Kind::Silent) {
                return fail(kExitNoAnswer, fmt::format("no node with serial {} answered Select (is it on the bus? "
                                                       "`dcos-config scan` lists the serial numbers): {}",
                                                       options.serial, error.why));
            }
            return failWith(error, who);
        }
    } else {
        who = fmt::format("node {}", options.node);
    }
    if (const ConfigError error = client.identify(node)) {
        return failWith(error, who);
    }
    if (options.bySerial && node.serial != options.serial) {
        // Another host's Select came in between: do not change that node.
        return fail(kExitRefused, fmt::format("the selected node has serial {}, not {}: is another host scanning "
                                              "the bus?",
                                              node.serial, options.serial));
    }
    who = options.bySerial ? fmt::format("node {} (serial {})", node.nodeId, node.serial)
                           : fmt::format("node {}", node.nodeId);
    return kExitOk;
}

// A node reached for one command: the link, the client on it, the
// selection that ends (Deselect) when this goes, and who the node is.
// Members go in reverse order, so the Deselect still has its client.
struct ReachedNode {
    std::unique_ptr<hostconfig::CanConfigLink> link;
    std::unique_ptr<ConfigClient> client;
    std::unique_ptr<Selection> selection;
    NodeIdentity node;
    std::string who;
};

// Opens the link to the node -n or --serial names, selects it in the
// latter case, and identifies it; an exit status other than kExitOk when
// any step fails (it has been said why).
int reachNode(const Options& options, ReachedNode& reached)
{
    int code = kExitOk;
    reached.link =
        openLink(options, options.bySerial ? can::MessageIdentifier::kBroadcast : static_cast<uint8_t>(options.node),
                 code);
    if (!reached.link) {
        return code;
    }
    reached.client = std::make_unique<ConfigClient>(
        *reached.link, hostconfig::ClientOptions{std::chrono::milliseconds(options.timeoutMs), options.retries});
    reached.selection = std::make_unique<Selection>(*reached.client);
    return reach(*reached.client, *reached.selection, options, reached.node, reached.who);
}

int keygen(const Options& options)
{
    std::string error;
    std::optional<ConfigurationKey> key = hostimage::newConfigurationKey(error);
    if (!key) {
        return fail(kExitNotAvailable, error);
    }
    const bool written = hostimage::writeConfigurationKey(options.output, *key, options.force, error);
    key->fill(0);
    if (!written) {
        return fail(kExitNotAvailable, error);
    }
    if (options.json) {
        fmt::print("{}\n", nlohmann::json{{"key_file", options.output}}.dump());
    } else {
        fmt::print("configuration key written to {} (readable by its owner only); give it to dcos-card create "
                   "--config-key, and keep it: every change dcos-config makes on that node needs it (-K)\n",
                   options.output);
    }
    return kExitOk;
}

int scan(const Options& options)
{
    int code = kExitOk;
    std::unique_ptr<hostconfig::CanConfigLink> link = openLink(options, can::MessageIdentifier::kBroadcast, code);
    if (!link) {
        return code;
    }
    ConfigClient client(*link, {std::chrono::milliseconds(options.timeoutMs), options.retries});
    std::vector<uint32_t> serials;
    if (const ConfigError error = client.scan(serials)) {
        return failWith(error, "the scan");
    }
    nlohmann::json nodes = nlohmann::json::array();
    bool missing = false;
    {
        Selection selection(client);
        for (const uint32_t serial : serials) {
            const std::string who = fmt::format("serial {}", serial);
            hostconfig::SelectedNode selected;
            selection.begin();
            if (const ConfigError error = client.select(serial, selected)) {
                warn(error.kind == ConfigError::Kind::Silent
                         ? fmt::format("serial {} answered the scan but not Select (did it leave the bus?): {}",
                                       serial, error.why)
                         : describe(error, who));
                missing = true;
                continue;
            }
            NodeIdentity node;
            if (const ConfigError error = client.identify(node)) {
                warn(describe(error, fmt::format("node {} ({})", selected.nodeId, who)));
                missing = true;
                continue;
            }
            if (node.serial != serial) {
                warn(fmt::format("selected serial {}, but serial {} answered: is another host scanning the bus?",
                                 serial, node.serial));
                missing = true;
                continue;
            }
            if (options.json) {
                nodes.push_back(identityJson(node));
            } else {
                fmt::print("{}\n", hostconfig::scanLine(node));
            }
        }
    }
    if (options.json) {
        fmt::print("{}\n", nodes.dump());
    }
    if (serials.empty()) {
        return fail(kExitNoAnswer, "no node answered the scan (a node whose card has serial number 0 takes no part: "
                                   "reach it with -n)");
    }
    return missing ? kExitNoAnswer : kExitOk;
}

int info(const Options& options)
{
    int code = kExitOk;
    std::optional<ConfigurationKey> key;
    if (!options.keyFile.empty()) {
        key = readKey(options, code);
        if (!key) {
            return code;
        }
    }
    ReachedNode reached;
    if (const int status = reachNode(options, reached); status != kExitOk) {
        return status;
    }
    ConfigClient& client = *reached.client;
    const NodeIdentity& node = reached.node;
    const std::string& who = reached.who;
    if (!key && node.queriesClosed()) {
        return fail(kExitUsage, fmt::format("{} has closed queries (dcos-card create --closed-queries): give its "
                                            "configuration key with -K KEYFILE to read its configuration",
                                            who));
    }
    NodeConfiguration configuration;
    if (const ConfigError error = client.getConfiguration(node, key ? &*key : nullptr, configuration)) {
        return failWith(error, who);
    }
    if (options.json) {
        nlohmann::json out = identityJson(node);
        out["configuration"] = configurationJson(configuration);
        fmt::print("{}\n", out.dump());
        return kExitOk;
    }
    fmt::print("serial          {}\n", node.serial);
    fmt::print("node            {}\n", node.nodeId);
    fmt::print("can-node        {}\n", node.canNode);
    fmt::print("board           {}\n", hostconfig::boardText(node.board));
    fmt::print("version         {}\n", node.version);
    fmt::print("protocol        {}\n", node.protocol);
    fmt::print("key             {}\n", node.hasKey() ? "yes" : "no (nothing can be changed over the bus)");
    fmt::print("queries         {}\n", node.queriesClosed() ? "closed" : "open");
    fmt::print("locked out      {}\n", node.lockedOut() ? "yes" : "no");
    fmt::print("configuration   sequence {}, from the next start:\n", configuration.sequence);
    fmt::print("  node id       {}\n", nodeIdText(configuration.nodeId));
    fmt::print("  CAN bit rate  {}\n", bitRateText(configuration.bitRate));
    fmt::print("  lockout       {} s\n", configuration.lockoutSeconds != 0 ? configuration.lockoutSeconds
                                                                            : sei::SeiAuthenticator::kDefaultLockoutSeconds);
    fmt::print("  command line  {}\n", configuration.commandLine);
    return kExitOk;
}

// What the authenticated commands change.
enum class Change { NodeId, BitRate, Restart };

int change(const Options& options, Change what)
{
    int code = kExitOk;
    const std::optional<ConfigurationKey> key = readKey(options, code);
    if (!key) {
        return code;
    }
    ReachedNode reached;
    if (const int status = reachNode(options, reached); status != kExitOk) {
        return status;
    }
    ConfigClient& client = *reached.client;
    const NodeIdentity& node = reached.node;
    const std::string& who = reached.who;
    uint32_t sequence = 0;
    ConfigError error;
    switch (what) {
    case Change::NodeId: error = client.setNodeId(node, *key, options.newNodeId, sequence); break;
    case Change::BitRate: error = client.setBitRate(node, *key, options.bitRate, sequence); break;
    case Change::Restart: error = client.restart(node, *key); break;
    }
    if (error) {
        return failWith(error, who);
    }
    if (options.json) {
        nlohmann::json out{{"node", node.nodeId}, {"serial", node.serial}};
        if (what == Change::Restart) {
            out["restarted"] = true;
        } else {
            out[what == Change::NodeId ? "node_id" : "bit_rate"] =
                what == Change::NodeId ? options.newNodeId : options.bitRate;
            out["sequence"] = sequence;
        }
        fmt::print("{}\n", out.dump());
        return kExitOk;
    }
    switch (what) {
    case Change::NodeId:
        fmt::print("{}: node id {} written (configuration sequence {}); it takes effect when the node next starts "
                   "(dcos-config restart)\n",
                   who, options.newNodeId, sequence);
        break;
    case Change::BitRate:
        fmt::print("{}: CAN bit rate {} bit/s written (configuration sequence {}); it takes effect when the node next "
                   "starts (dcos-config restart), and every node on the bus must use the same\n",
                   who, options.bitRate, sequence);
        break;
    case Change::Restart: fmt::print("{}: restarting\n", who); break;
    }
    return kExitOk;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-config: find the controllers on a CAN bus, read what they are, and change their node id and "
                 "CAN bit rate",
                 "dcos-config"};
    app.set_version_flag("--version", std::string("dcos-config ") + dcos::versionString);
    app.footer("exit status: 0 done, 1 refused by the node (its status: wrong key, locked out, no key, a value it "
               "cannot take), 2 bad arguments, 3 interface or file not available, 4 no answer (the node silent, or "
               "nobody acknowledged)\n"
               "interfaces: can0 (SocketCAN), slcan:/dev/ttyACM0[@bitrate], lab:/path/hub.sock:can0 (the lab bus)\n"
               "scan finds nodes by serial number: a node whose card has serial number 0 (dcos-card create without "
               "--serial) takes no part in it and is reached with -n only");
    // The node and key options may come before or after the command
    // (`dcos-config -i can0 info -n 3` and `dcos-config -i can0 -n 3 info`).
    app.fallthrough();
    app.require_subcommand(1);
    Options options;
    app.add_option("-i,--interface", options.interface, "the CAN interface the nodes are on");
    app.add_option("--source", options.source, "this tool's CAN node number")
        ->check(CLI::Range(0, int{can::MessageIdentifier::kMaxNodeNumber}));
    app.add_option("--priority", options.priority, "the bus priority of the transfers, 0 (most urgent) to 31")
        ->check(CLI::Range(0, int{can::MessageIdentifier::kLowestPriority}));
    app.add_flag("--kernel-isotp", options.kernelIsoTp,
                 "segment with the Linux kernel's ISO-TP socket (can-isotp), not our own; SocketCAN only");
    app.add_option("--timeout-ms", options.timeoutMs, "how long to wait for each answer")
        ->check(CLI::Range(10L, 600000L));
    app.add_option("--retries", options.retries, "how often to send a request again on silence")
        ->check(CLI::Range(0, 100));
    app.add_option("--probe-ms", options.probeMs, "scan: how long to wait for the answers to each probe")
        ->check(CLI::Range(1L, 10000L));
    app.add_flag("--json", options.json, "machine-readable output: one JSON value");
    CLI::Option* nodeOption =
        app.add_option("-n,--node", options.node, "the node's CAN node number")
            ->check(CLI::Range(0, int{can::MessageIdentifier::kMaxNodeNumber}));
    CLI::Option* serialOption = app.add_option(
        "--serial", options.serial,
        "the node's serial number (as scan lists it): selects it on the broadcast address, for nodes that share a "
        "CAN node number");
    nodeOption->excludes(serialOption);
    app.add_option("-K,--key-file", options.keyFile, "the node's configuration key file (keygen makes one)");

    CLI::App* keygenCommand =
        app.add_subcommand("keygen", "make a new configuration key file (64 hex digits, mode 0600) for dcos-card "
                                     "create --config-key; needs no -i");
    keygenCommand->add_option("-o,--output", options.output, "the key file to write")->required();
    keygenCommand->add_flag("--force", options.force, "replace an existing file");
    CLI::App* scanCommand =
        app.add_subcommand("scan", "list every node on the bus by serial number: one line each, or a JSON array");
    CLI::App* infoCommand = app.add_subcommand(
        "info", "show a node's identity and configuration (-n or --serial; -K when its queries are closed)");
    CLI::App* setNodeCommand =
        app.add_subcommand("set-node", "write a node's node id (1 to 254) for its next start (-K)");
    setNodeCommand->add_option("node-id", options.newNodeId, "the new node id")
        ->required()
        ->check(CLI::Range(1, 254));
    CLI::App* setBitRateCommand =
        app.add_subcommand("set-bitrate", "write a node's CAN bit rate (bit/s) for its next start (-K)");
    setBitRateCommand->add_option("rate", options.bitRate, "the new bit rate in bit/s, one the node's controller "
                                                            "makes exactly (125000, 250000, 500000, 1000000 ...)")
        ->required()
        ->check(CLI::Range(1u, 0xFFFFFFFFu));
    CLI::App* restartCommand = app.add_subcommand("restart", "restart a node, so a written node id or bit rate "
                                                             "takes effect (-K)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == 0 ? kExitOk : kExitUsage;
    }
    options.bySerial = serialOption->count() != 0;
    if (*keygenCommand) {
        return keygen(options);
    }
    if (options.interface.empty()) {
        return fail(kExitUsage, "say which CAN interface the nodes are on: -i can0, -i slcan:/dev/ttyACM0 or "
                                "-i lab:/path/hub.sock:can0");
    }
    if (*scanCommand) {
        return scan(options);
    }
    if (options.node < 0 && !options.bySerial) {
        return fail(kExitUsage, "say which node: -n NODE (its CAN node number) or --serial S (its serial number)");
    }
    if (options.node == options.source) {
        return fail(kExitUsage, fmt::format("the node's CAN node number ({}) must differ from the tool's (--source)",
                                            options.node));
    }
    if (options.bySerial && options.serial == 0) {
        return fail(kExitUsage, "serial number 0 is no serial number: reach that node with -n");
    }
    if (*infoCommand) {
        return info(options);
    }
    if (options.keyFile.empty()) {
        return fail(kExitUsage, "changes need the node's configuration key: -K KEYFILE");
    }
    if (*setNodeCommand) {
        return change(options, Change::NodeId);
    }
    if (*setBitRateCommand) {
        return change(options, Change::BitRate);
    }
    if (*restartCommand) {
        return change(options, Change::Restart);
    }
    return fail(kExitUsage, "no command");
}
