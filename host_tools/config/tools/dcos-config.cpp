// dcos-config: find the controllers on a CAN bus, read what they are, and
// change their node id and CAN bit rate (docs/protocols/config.md).
//
//     dcos-config keygen -o FILE [--force]
//     dcos-config -i IFACE scan
//     dcos-config -i IFACE info (-n NODE | --serial S) [-K KEYFILE]
//     dcos-config -i IFACE set-node (-n NODE | --serial S) -K KEYFILE NEWID
//     dcos-config -i IFACE set-bitrate (-n NODE | --serial S) -K KEYFILE RATE
//     dcos-config -i IFACE restart (-n NODE | --serial S) -K KEYFILE
//     dcos-config -i IFACE objects|find|show|stats ... (-n NODE | --serial S) [-K KEYFILE]
//     dcos-config -i IFACE create|delete|add-objects|task-create|task-start|task-stop|task-kill ... -K KEYFILE
//     dcos-config -i IFACE save (-n NODE | --serial S) [-K KEYFILE] FILE.toml
//     dcos-config -i IFACE restore (-n NODE | --serial S) -K KEYFILE FILE.toml
//     dcos-config -i IFACE switch-bitrate [--delay-ms MS]
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
#include <hostconfig/ConfigurationFile.hpp>
#include <hostconfig/NodeObjects.hpp>
#include <hostconfig/NodeSession.hpp>

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
#include <fstream>
#include <memory>
#include <sstream>
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

using hostconfig::kExitNoAnswer;
using hostconfig::kExitNotAvailable;
using hostconfig::kExitOk;
using hostconfig::kExitRefused;
using hostconfig::kExitUsage;
using hostconfig::describe;
using hostconfig::exitCodeOf;

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
    // The object commands' arguments.
    std::string kind;
    std::string name;
    std::string target;
    std::string file;
    hostconfig::ObjectSpec object;
    std::string visibility = "local";
    hostconfig::TaskSpec task;
    uint16_t count = 0;
    int delayMs = 500;
};

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

// A node reached for one command: the link, the client on it, the
// selection that ends (Deselect) when this goes, and who the node is.
// Members go in reverse order, so the Deselect still has its client.
struct ReachedNode {
    std::unique_ptr<hostconfig::CanConfigLink> link;
    std::unique_ptr<ConfigClient> client;
    std::unique_ptr<hostconfig::Selection> selection;
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
    reached.selection = std::make_unique<hostconfig::Selection>(*reached.client, warn);
    const hostconfig::ReachOutcome outcome = hostconfig::reachNode(
        *reached.client, *reached.selection, {options.bySerial, options.serial, options.node}, reached.node,
        reached.who);
    return outcome.code == kExitOk ? kExitOk : fail(outcome.code, outcome.message);
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
        hostconfig::Selection selection(client, warn);
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

// The key -K names, when given; @p code is set when it cannot be read.
std::optional<ConfigurationKey> optionalKey(const Options& options, int& code)
{
    return options.keyFile.empty() ? std::nullopt : readKey(options, code);
}

// Reaches the node for a query: with the key when given, and a clear word
// when the node's queries are closed and no key was given.
int reachForQuery(const Options& options, ReachedNode& reached, const std::optional<ConfigurationKey>& key)
{
    if (const int status = reachNode(options, reached); status != kExitOk) {
        return status;
    }
    if (!key && reached.node.queriesClosed()) {
        return fail(kExitUsage, fmt::format("{} has closed queries (dcos-card create --closed-queries): give its "
                                            "configuration key with -K KEYFILE",
                                            reached.who));
    }
    return kExitOk;
}

// A node reached for queries: its key when -K gave one, and its objects.
// Members go in reverse order, so the objects go before their client.
struct QueriedNode {
    std::optional<ConfigurationKey> key;
    ReachedNode reached;
    std::unique_ptr<hostconfig::NodeObjects> objects;
};

int queryNode(const Options& options, QueriedNode& queried)
{
    int code = kExitOk;
    queried.key = optionalKey(options, code);
    if (code != kExitOk) {
        return code;
    }
    if (const int status = reachForQuery(options, queried.reached, queried.key); status != kExitOk) {
        return status;
    }
    queried.objects = std::make_unique<hostconfig::NodeObjects>(*queried.reached.client, queried.reached.node,
                                                                queried.key ? &*queried.key : nullptr);
    return kExitOk;
}

std::optional<dcos::ObjectType> kindArgument(const std::string& word)
{
    const std::optional<dcos::ObjectType> kind = hostconfig::kindFromName(word);
    if (!kind) {
        std::string known;
        for (const dcos::ObjectType k : hostconfig::listedKinds()) {
            known += (known.empty() ? "" : ", ") + hostconfig::kindName(static_cast<uint8_t>(k));
        }
        fail(kExitUsage, fmt::format("'{}' is no object type; the types are {}", word, known));
    }
    return kind;
}

// The object @p text names: an id (0x0005a001 or decimal), or KIND:NAME, or
// (with @p fallback) a name of that kind, as the node finds it.
int resolveObject(hostconfig::NodeObjects& objects, const std::string& text,
                  std::optional<dcos::ObjectType> fallback, const std::string& who, uint32_t& id)
{
    if (const std::optional<uint32_t> parsed = hostconfig::parseId(text)) {
        id = *parsed;
        return kExitOk;
    }
    std::optional<dcos::ObjectType> kind = fallback;
    std::string name = text;
    if (const size_t colon = text.find(':'); colon != std::string::npos) {
        kind = kindArgument(text.substr(0, colon));
        if (!kind) {
            return kExitUsage;
        }
        name = text.substr(colon + 1);
    }
    if (!kind || name.empty() || name.size() > sei::kSeiMaxName) {
        return fail(kExitUsage, fmt::format("'{}' is neither an id (0x0005a001) nor TYPE:NAME with a name of 1 to {} "
                                            "characters",
                                            text, sei::kSeiMaxName));
    }
    if (const ConfigError error = objects.find(*kind, name, id)) {
        return failWith(error, who);
    }
    return kExitOk;
}

nlohmann::json entryJson(const hostconfig::ObjectEntry& entry)
{
    return {{"id", hostconfig::idText(entry.id)},
            {"type", hostconfig::kindName(entry.type)},
            {"name", entry.name},
            {"owner", entry.owner == 0 ? std::string("system") : hostconfig::idText(entry.owner)}};
}

int listObjects(const Options& options)
{
    std::vector<dcos::ObjectType> kinds = hostconfig::listedKinds();
    if (!options.kind.empty()) {
        const std::optional<dcos::ObjectType> kind = kindArgument(options.kind);
        if (!kind) {
            return kExitUsage;
        }
        kinds = {*kind};
    }
    QueriedNode queried;
    if (const int status = queryNode(options, queried); status != kExitOk) {
        return status;
    }
    hostconfig::NodeObjects& objects = *queried.objects;
    const ReachedNode& reached = queried.reached;
    nlohmann::json out = nlohmann::json::array();
    if (!options.json) {
        fmt::print("{:<12} {:<10} {:<16} {}\n", "id", "type", "name", "owner");
    }
    for (const dcos::ObjectType kind : kinds) {
        std::vector<hostconfig::ObjectEntry> entries;
        if (const ConfigError error = objects.list(kind, entries)) {
            return failWith(error, reached.who);
        }
        for (const hostconfig::ObjectEntry& entry : entries) {
            if (options.json) {
                out.push_back(entryJson(entry));
            } else {
                fmt::print("{:<12} {:<10} {:<16} {}\n", hostconfig::idText(entry.id), hostconfig::kindName(entry.type),
                           entry.name.empty() ? "-" : entry.name,
                           entry.owner == 0 ? std::string("system") : hostconfig::idText(entry.owner));
            }
        }
    }
    if (options.json) {
        fmt::print("{}\n", out.dump());
    }
    return kExitOk;
}

int findObject(const Options& options)
{
    const std::optional<dcos::ObjectType> kind = kindArgument(options.kind);
    if (!kind) {
        return kExitUsage;
    }
    QueriedNode queried;
    if (const int status = queryNode(options, queried); status != kExitOk) {
        return status;
    }
    uint32_t id = 0;
    if (const ConfigError error = queried.objects->find(*kind, options.name, id)) {
        return failWith(error, queried.reached.who);
    }
    if (options.json) {
        fmt::print("{}\n", nlohmann::json{{"id", hostconfig::idText(id)}, {"type", options.kind},
                                          {"name", options.name}}.dump());
    } else {
        fmt::print("{}\n", hostconfig::idText(id));
    }
    return kExitOk;
}

int showObject(const Options& options)
{
    QueriedNode queried;
    if (const int status = queryNode(options, queried); status != kExitOk) {
        return status;
    }
    hostconfig::NodeObjects& objects = *queried.objects;
    const ReachedNode& reached = queried.reached;
    uint32_t id = 0;
    if (const int status = resolveObject(objects, options.target, std::nullopt, reached.who, id); status != kExitOk) {
        return status;
    }
    hostconfig::ObjectDetails details;
    if (const ConfigError error = objects.info(id, details)) {
        return failWith(error, reached.who);
    }
    const char* known = hostconfig::visibilityName(details.visibility);
    const std::string visibility = known != nullptr ? known : "?";
    const bool task = details.type == static_cast<uint8_t>(dcos::ObjectType::Task);
    if (options.json) {
        nlohmann::json out{{"id", hostconfig::idText(details.id)},
                           {"type", hostconfig::kindName(details.type)},
                           {"name", details.name},
                           {"visibility", visibility},
                           {"owner", details.owner == 0 ? std::string("system") : hostconfig::idText(details.owner)}};
        if (task) {
            out["state"] = hostconfig::taskStateName(details.state);
        }
        for (const auto& [name, value] : details.figures) {
            out[name] = value;
        }
        fmt::print("{}\n", out.dump());
        return kExitOk;
    }
    fmt::print("{:<22} {}\n", "id", hostconfig::idText(details.id));
    fmt::print("{:<22} {}\n", "type", hostconfig::kindName(details.type));
    fmt::print("{:<22} {}\n", "name", details.name.empty() ? "-" : details.name);
    fmt::print("{:<22} {}\n", "visibility", visibility);
    fmt::print("{:<22} {}\n", "owner", details.owner == 0 ? std::string("system") : hostconfig::idText(details.owner));
    if (task) {
        fmt::print("{:<22} {}\n", "state", hostconfig::taskStateName(details.state));
    }
    for (const auto& [name, value] : details.figures) {
        fmt::print("{:<22} {}\n", name, value);
    }
    return kExitOk;
}

int statistics(const Options& options)
{
    QueriedNode queried;
    if (const int status = queryNode(options, queried); status != kExitOk) {
        return status;
    }
    hostconfig::NodeStatistics stats;
    if (const ConfigError error = queried.objects->statistics(stats)) {
        return failWith(error, queried.reached.who);
    }
    if (options.json) {
        nlohmann::json tables = nlohmann::json::object();
        for (const hostconfig::NodeStatistics::Table& table : stats.tables) {
            tables[hostconfig::kindName(table.type)] = {{"used", table.used}, {"active", table.active}};
        }
        fmt::print("{}\n", nlohmann::json{{"uptime_ns", stats.uptimeNs},
                                          {"task_switches", stats.taskSwitches},
                                          {"stack_free", stats.stackFree},
                                          {"tables", tables}}
                               .dump());
        return kExitOk;
    }
    fmt::print("uptime          {}.{:03} s\n", stats.uptimeNs / 1000000000u, (stats.uptimeNs / 1000000u) % 1000u);
    fmt::print("task switches   {}\n", stats.taskSwitches);
    fmt::print("stack free      {} bytes\n", stats.stackFree);
    for (const hostconfig::NodeStatistics::Table& table : stats.tables) {
        fmt::print("{:<15} {} of {} slots used\n", hostconfig::kindName(table.type), table.used, table.active);
    }
    return kExitOk;
}

// The object and task commands that change something.
enum class Manage { Create, Delete, AddObjects, TaskCreate, TaskStart, TaskStop, TaskKill };

int manage(const Options& options, Manage what)
{
    int code = kExitOk;
    const std::optional<ConfigurationKey> key = readKey(options, code);
    if (!key) {
        return code;
    }
    std::optional<dcos::ObjectType> kind;
    if (what == Manage::Create || what == Manage::AddObjects) {
        kind = kindArgument(options.kind);
        if (!kind) {
            return kExitUsage;
        }
    }
    hostconfig::ObjectSpec object = options.object;
    if (what == Manage::Create) {
        object.kind = *kind;
        object.name = options.name;
        const std::optional<uint8_t> visibility = hostconfig::visibilityFromName(options.visibility);
        if (!visibility) {
            return fail(kExitUsage, fmt::format("visibility '{}' is none of local, regional, global", options.visibility));
        }
        object.visibility = *visibility;
    }
    ReachedNode reached;
    if (const int status = reachNode(options, reached); status != kExitOk) {
        return status;
    }
    hostconfig::NodeChanges changes(*reached.client, reached.node, *key);
    hostconfig::NodeObjects objects(*reached.client, reached.node, &*key);
    uint32_t id = 0;
    ConfigError error;
    std::string done;
    switch (what) {
    case Manage::Create:
        error = changes.createObject(object, id);
        done = fmt::format("{} {} created", hostconfig::kindName(static_cast<uint8_t>(object.kind)), object.name);
        break;
    case Manage::AddObjects:
        error = changes.addObjects(*kind, options.count);
        done = fmt::format("{} more {} slots", options.count, hostconfig::kindName(static_cast<uint8_t>(*kind)));
        break;
    case Manage::TaskCreate:
        error = changes.createTask(options.task, id);
        done = fmt::format("task {} created, running {}", options.task.name, options.task.entry);
        break;
    case Manage::Delete:
    case Manage::TaskStart:
    case Manage::TaskStop:
    case Manage::TaskKill: {
        const std::optional<dcos::ObjectType> fallback =
            what == Manage::Delete ? std::nullopt : std::optional<dcos::ObjectType>(dcos::ObjectType::Task);
        if (const int status = resolveObject(objects, options.target, fallback, reached.who, id); status != kExitOk) {
            return status;
        }
        const sei::SeiCommand command = what == Manage::Delete      ? sei::SeiCommand::DeleteObject
                                        : what == Manage::TaskStart ? sei::SeiCommand::StartTask
                                        : what == Manage::TaskStop  ? sei::SeiCommand::StopTask
                                                                    : sei::SeiCommand::KillTask;
        error = changes.onObject(command, id);
        done = fmt::format("{} {}", hostconfig::idText(id),
                           what == Manage::Delete      ? "deleted"
                           : what == Manage::TaskStart ? "started"
                           : what == Manage::TaskStop  ? "stopped"
                                                       : "killed");
        break;
    }
    }
    if (error) {
        if (error.kind == ConfigError::Kind::Silent &&
            (what == Manage::Create || what == Manage::TaskCreate || what == Manage::AddObjects)) {
            return fail(kExitNoAnswer, fmt::format("no reply from {}: it may have done it all the same, so it was not "
                                                   "asked again; look with `dcos-config objects` ({})",
                                                   reached.who, error.why));
        }
        return failWith(error, reached.who);
    }
    if (options.json) {
        nlohmann::json out{{"node", reached.node.nodeId}, {"serial", reached.node.serial}};
        if (id != 0) {
            out["id"] = hostconfig::idText(id);
        }
        fmt::print("{}\n", out.dump());
    } else {
        fmt::print("{}: {}{}\n", reached.who, done, id != 0 && what != Manage::Delete && what != Manage::TaskStart &&
                                                            what != Manage::TaskStop && what != Manage::TaskKill
                                                        ? fmt::format(" as {}", hostconfig::idText(id))
                                                        : std::string());
    }
    return kExitOk;
}

int save(const Options& options)
{
    QueriedNode queried;
    if (const int status = queryNode(options, queried); status != kExitOk) {
        return status;
    }
    const std::optional<ConfigurationKey>& key = queried.key;
    const ReachedNode& reached = queried.reached;
    ConfigClient& client = *reached.client;
    hostconfig::SavedNode saved;
    saved.serial = reached.node.serial;
    if (const ConfigError error = client.getConfiguration(reached.node, key ? &*key : nullptr, saved.configuration)) {
        return failWith(error, reached.who);
    }
    hostconfig::NodeObjects& objects = *queried.objects;
    // The named objects a host can make again: semaphores, ports and
    // publishers, each as it was created.
    for (const dcos::ObjectType kind :
         {dcos::ObjectType::Semaphore, dcos::ObjectType::MessagePort, dcos::ObjectType::DsmPublisher}) {
        std::vector<hostconfig::ObjectEntry> entries;
        if (const ConfigError error = objects.list(kind, entries)) {
            return failWith(error, reached.who);
        }
        for (const hostconfig::ObjectEntry& entry : entries) {
            if (entry.name.empty()) {
                continue; // Nothing could find it again by name.
            }
            hostconfig::ObjectDetails details;
            if (const ConfigError error = objects.info(entry.id, details)) {
                return failWith(error, reached.who);
            }
            hostconfig::ObjectSpec spec;
            spec.kind = kind;
            spec.name = entry.name;
            spec.visibility = details.visibility;
            if (kind == dcos::ObjectType::Semaphore) {
                const uint64_t settings = details.figure("settings");
                spec.counting = (settings & sei::kSeiSemaphoreCounting) != 0;
                spec.inheritance = (settings & sei::kSeiSemaphoreInheritance) != 0;
                spec.fifo = (settings & sei::kSeiSemaphoreFifo) != 0;
                spec.initialCount = static_cast<uint32_t>(details.figure("count"));
            } else if (kind == dcos::ObjectType::MessagePort) {
                spec.fifo = details.figure("order_fifo") != 0;
            }
            saved.objects.push_back(spec);
        }
    }
    const std::string header = fmt::format(
        "A DCOS node's configuration, saved by dcos-config {} from {}, board {}, firmware {}.\n"
        "dcos-config restore -K KEYFILE writes [node] into the node's card (it takes effect at the next start) and\n"
        "creates every object and task below that the node has not got by its name. Semaphores, ports and publishers\n"
        "are the node's named ones at the time of saving (its application's too: restore leaves those present as\n"
        "they are); a semaphore's initial_count is its count then. Tasks are not saved, since a node does not say\n"
        "which entry point a task runs: add a [[task]] with name, entry (a task the image's application declares),\n"
        "priority, stack_size and argument for each one restore should start.",
        dcos::versionString, reached.who, hostconfig::boardText(reached.node.board), reached.node.version);
    const std::string text = hostconfig::writeSavedNode(saved, header);
    std::ofstream out(options.file, std::ios::binary | std::ios::trunc);
    if (!out || !(out << text) || !out.flush()) {
        return fail(kExitNotAvailable, fmt::format("cannot write {}", options.file));
    }
    if (options.json) {
        fmt::print("{}\n", nlohmann::json{{"file", options.file},
                                          {"node", reached.node.nodeId},
                                          {"serial", reached.node.serial},
                                          {"objects", saved.objects.size()}}
                               .dump());
    } else {
        fmt::print("{}: configuration and {} named objects saved to {}\n", reached.who, saved.objects.size(),
                   options.file);
    }
    return kExitOk;
}

int restore(const Options& options)
{
    int code = kExitOk;
    const std::optional<ConfigurationKey> key = readKey(options, code);
    if (!key) {
        return code;
    }
    std::ifstream in(options.file, std::ios::binary);
    if (!in) {
        return fail(kExitNotAvailable, fmt::format("cannot read {}", options.file));
    }
    std::ostringstream text;
    text << in.rdbuf();
    hostconfig::SavedNode saved;
    if (const std::optional<std::string> error = hostconfig::readSavedNode(text.str(), options.file, saved)) {
        return fail(kExitUsage, *error);
    }
    ReachedNode reached;
    if (const int status = reachNode(options, reached); status != kExitOk) {
        return status;
    }
    if (saved.serial != 0 && saved.serial != reached.node.serial) {
        warn(fmt::format("{} was saved from serial {}; restoring it to serial {}", options.file, saved.serial,
                         reached.node.serial));
    }
    hostconfig::NodeChanges changes(*reached.client, reached.node, *key);
    hostconfig::NodeObjects objects(*reached.client, reached.node, &*key);
    uint32_t sequence = 0;
    if (const ConfigError error = changes.setConfiguration(saved.configuration, sequence)) {
        return failWith(error, reached.who);
    }
    nlohmann::json created = nlohmann::json::array();
    nlohmann::json present = nlohmann::json::array();
    // Each object and task by its name: one the node has is left as it is,
    // so that a restore done twice creates nothing the second time.
    const auto ensure = [&](dcos::ObjectType kind, const std::string& name, auto make) -> int {
        const std::string label = fmt::format("{} {}", hostconfig::kindName(static_cast<uint8_t>(kind)), name);
        uint32_t id = 0;
        const ConfigError found = objects.find(kind, name, id);
        if (!found) {
            present.push_back(label);
            return kExitOk;
        }
        if (found.kind != ConfigError::Kind::Refused || found.status != sei::SeiStatus::KernelRefused ||
            found.kernelStatus != static_cast<uint8_t>(dcos::Status::NotFound)) {
            return failWith(found, reached.who);
        }
        if (const ConfigError error = make(id)) {
            warn(fmt::format("{} not restored: {}", label, describe(error, reached.who)));
            return exitCodeOf(error);
        }
        created.push_back({{"object", label}, {"id", hostconfig::idText(id)}});
        return kExitOk;
    };
    int worst = kExitOk;
    for (const hostconfig::ObjectSpec& spec : saved.objects) {
        const int status =
            ensure(spec.kind, spec.name, [&](uint32_t& id) { return changes.createObject(spec, id); });
        worst = worst == kExitOk ? status : worst;
    }
    for (const hostconfig::TaskSpec& spec : saved.tasks) {
        const int status =
            ensure(dcos::ObjectType::Task, spec.name, [&](uint32_t& id) { return changes.createTask(spec, id); });
        worst = worst == kExitOk ? status : worst;
    }
    if (options.json) {
        fmt::print("{}\n", nlohmann::json{{"node", reached.node.nodeId},
                                          {"serial", reached.node.serial},
                                          {"sequence", sequence},
                                          {"created", created},
                                          {"present", present}}
                               .dump());
    } else {
        fmt::print("{}: configuration written (sequence {}; node id {} and bit rate {} from the next start)\n",
                   reached.who, sequence, saved.configuration.nodeId, saved.configuration.bitRate);
        for (const nlohmann::json& item : created) {
            fmt::print("  created {} as {}\n", item["object"].get<std::string>(), item["id"].get<std::string>());
        }
        for (const nlohmann::json& item : present) {
            fmt::print("  present {}\n", item.get<std::string>());
        }
    }
    return worst;
}

int switchBitRate(const Options& options)
{
    int code = kExitOk;
    std::unique_ptr<hostconfig::CanConfigLink> link = openLink(options, can::MessageIdentifier::kBroadcast, code);
    if (!link) {
        return code;
    }
    ConfigClient client(*link, {std::chrono::milliseconds(options.timeoutMs), options.retries});
    if (const ConfigError error = client.activateBitRate(static_cast<uint16_t>(options.delayMs))) {
        return failWith(error, "the bus");
    }
    if (options.json) {
        fmt::print("{}\n", nlohmann::json{{"delay_ms", options.delayMs}}.dump());
    } else {
        fmt::print("ActivateBitRate sent: in {} ms every node switches to the bit rate its configuration names "
                   "(dcos-config set-bitrate); switch this interface too (SocketCAN: ip link set {} type can bitrate "
                   "RATE)\n",
                   options.delayMs, options.interface);
    }
    return kExitOk;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-config: find the controllers on a CAN bus, read what they are, change their node id and CAN "
                 "bit rate, and manage their objects and tasks",
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

    const std::string kinds = "task, timer, device, pool, heap, port, publisher or semaphore";
    CLI::App* objectsCommand = app.add_subcommand("objects", "list a node's objects: id, type, name, owner");
    objectsCommand->add_option("type", options.kind, "only objects of this type: " + kinds);
    CLI::App* findCommand = app.add_subcommand("find", "print the id of a node's object of a type by its name");
    findCommand->add_option("type", options.kind, kinds)->required();
    findCommand->add_option("name", options.name, "the object's name")->required();
    CLI::App* showCommand =
        app.add_subcommand("show", "show an object: owner, visibility, a task's state, and the figures of its type");
    showCommand->add_option("object", options.target, "an id (0x0005a001) or TYPE:NAME (semaphore:lock)")->required();
    CLI::App* statsCommand =
        app.add_subcommand("stats", "show a node's uptime, task switches, free stack memory and tables' use");
    CLI::App* createCommand =
        app.add_subcommand("create", "create a named semaphore, port or publisher, owned by the system (-K)");
    createCommand->add_option("type", options.kind, "semaphore, port or publisher")->required();
    createCommand->add_option("name", options.name, "its name, 1 to 15 characters")
        ->required()
        ->check(CLI::Validator([](std::string& name) { return name.size() <= sei::kSeiMaxName ? std::string()
                                                                                              : std::string("at most 15 characters"); },
                               "NAME", "name length"));
    createCommand->add_option("--initial", options.object.initialCount, "semaphores: the units available at first")
        ->default_val(1);
    createCommand->add_flag("--counting", options.object.counting, "semaphores: counting rather than binary");
    createCommand->add_flag("--inherit", options.object.inheritance, "binary semaphores: priority inheritance");
    createCommand->add_flag("--fifo", options.object.fifo,
                            "semaphores: waiters first come first served; ports: messages first in first out");
    createCommand->add_option("--visibility", options.visibility, "local, regional or global (NameToObject's reach)")
        ->default_val("local");
    CLI::App* deleteCommand = app.add_subcommand("delete", "delete an object; a task is killed (-K)");
    deleteCommand->add_option("object", options.target, "an id or TYPE:NAME")->required();
    CLI::App* addObjectsCommand =
        app.add_subcommand("add-objects", "activate more slots of a table, up to its reserve (AddObjects; -K)");
    addObjectsCommand->add_option("type", options.kind, kinds)->required();
    addObjectsCommand->add_option("count", options.count, "how many slots")->required()->check(CLI::Range(1, 4096));
    CLI::App* taskCreateCommand = app.add_subcommand(
        "task-create", "start a task running an entry point of the node's image: a task its application declares (-K)");
    taskCreateCommand->add_option("entry", options.task.entry, "the declared task whose code the new task runs")
        ->required();
    taskCreateCommand->add_option("name", options.task.name, "the new task's name, 1 to 15 characters")->required();
    taskCreateCommand->add_option("--prio", options.task.priority, "the task's priority, 0 (most urgent) to 31")
        ->default_val(16)
        ->check(CLI::Range(0, 31));
    taskCreateCommand->add_option("--stack", options.task.stackSize, "stack bytes")->default_val(4096);
    taskCreateCommand->add_option("--arg", options.task.argument, "the entry point's argument")->default_val(0);
    CLI::App* taskStartCommand = app.add_subcommand("task-start", "resume a stopped task (-K)");
    CLI::App* taskStopCommand = app.add_subcommand("task-stop", "suspend a task (-K)");
    CLI::App* taskKillCommand = app.add_subcommand("task-kill", "end a task; what it held is recovered (-K)");
    for (CLI::App* command : {taskStartCommand, taskStopCommand, taskKillCommand}) {
        command->add_option("task", options.target, "the task's id or name")->required();
    }
    CLI::App* saveCommand = app.add_subcommand(
        "save", "write a node's configuration and named objects to a TOML file (-K when its queries are closed)");
    saveCommand->add_option("file", options.file, "the TOML file to write")->required();
    CLI::App* restoreCommand = app.add_subcommand(
        "restore", "write a saved configuration into a node's card and create the objects and tasks it lacks (-K)");
    restoreCommand->add_option("file", options.file, "the TOML file dcos-config save wrote")->required();
    CLI::App* switchCommand = app.add_subcommand(
        "switch-bitrate", "make every node on the bus switch to its configured bit rate at once (set-bitrate each first)");
    switchCommand->add_option("--delay-ms", options.delayMs, "how long every node waits before it switches")
        ->default_val(500)
        ->check(CLI::Range(0, 65535));

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
    if (*switchCommand) {
        return switchBitRate(options);
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
    if (*objectsCommand) {
        return listObjects(options);
    }
    if (*findCommand) {
        return findObject(options);
    }
    if (*showCommand) {
        return showObject(options);
    }
    if (*statsCommand) {
        return statistics(options);
    }
    if (*saveCommand) {
        return save(options);
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
    if (*createCommand) {
        return manage(options, Manage::Create);
    }
    if (*deleteCommand) {
        return manage(options, Manage::Delete);
    }
    if (*addObjectsCommand) {
        return manage(options, Manage::AddObjects);
    }
    if (*taskCreateCommand) {
        return manage(options, Manage::TaskCreate);
    }
    if (*taskStartCommand) {
        return manage(options, Manage::TaskStart);
    }
    if (*taskStopCommand) {
        return manage(options, Manage::TaskStop);
    }
    if (*taskKillCommand) {
        return manage(options, Manage::TaskKill);
    }
    if (*restoreCommand) {
        return restore(options);
    }
    return fail(kExitUsage, "no command");
}
