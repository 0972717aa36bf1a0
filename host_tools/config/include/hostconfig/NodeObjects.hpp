// dcos-config's view of a node's objects and tasks (docs/protocols/config.md,
// "Objects and tasks"): the management commands of the system engineering
// interface agent (seed 7.14) as calls on a ConfigClient that own their
// results, and the words and numbers an engineer types and reads for them
// (object types, task states, the kernel's refusals). Errors are values.
#pragma once

#include <hostconfig/ConfigClient.hpp>
#include <hostconfig/ConfigRequest.hpp>

#include <sei/SeiMessage.hpp>

#include <dcos/ObjectId.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hostconfig {

/// The object types, as the node numbers them in every id.
using dcos::ObjectType;

/// Every listed kind, in the order `dcos-config objects` prints them.
const std::vector<ObjectType>& listedKinds();
/// "task", "timer", "device", "pool", "heap", "port", "publisher", "semaphore";
/// "type-N" for a number this tool does not know.
std::string kindName(uint8_t type);
/// The kind a word names (the names above), or nothing.
std::optional<ObjectType> kindFromName(const std::string& name);
/// "local", "regional" or "global" (dcos::Visibility); null for another value.
const char* visibilityName(uint8_t visibility);
/// The visibility a word names (the names above), or nothing.
std::optional<uint8_t> visibilityFromName(const std::string& name);
/// "ready", "suspended", ... (dcos::TaskState).
std::string taskStateName(uint8_t state);
/// The kernel's words for its status (dcos::statusName).
std::string kernelStatusText(uint8_t status);
/// An id as every DCOS listing prints it: 0x and eight hex digits.
std::string idText(uint32_t id);
/// An id typed by an engineer: 0x… hex or decimal; nothing when it is neither.
std::optional<uint32_t> parseId(const std::string& text);

/// One object in a listing.
struct ObjectEntry {
    uint8_t type = 0;
    uint32_t id = 0;
    uint32_t owner = 0; ///< 0 for the system.
    std::string name;
};

/// What ObjectInfo tells: the figures with their names for the type
/// (docs/protocols/config.md, "ObjectInfo's figures").
struct ObjectDetails {
    uint8_t type = 0;
    uint32_t id = 0;
    uint8_t state = 0;
    uint8_t visibility = 0; ///< 0 local, 1 regional, 2 global.
    uint32_t owner = 0;
    std::string name;
    std::vector<std::pair<std::string, uint64_t>> figures;

    /// The figure named @p name, or 0.
    uint64_t figure(const std::string& name) const;
};

/// The names of ObjectInfo's figures for @p type, in order.
const std::vector<std::string>& figureNames(uint8_t type);

/// What NodeStatistics tells.
struct NodeStatistics {
    uint64_t uptimeNs = 0;
    uint32_t taskSwitches = 0;
    uint32_t stackFree = 0;
    struct Table {
        uint8_t type = 0;
        uint16_t used = 0;
        uint16_t active = 0;
    };
    std::vector<Table> tables;
};

/// Queries of one node: with a MAC under @p key when given (needed where
/// the node's queries are closed).
class NodeObjects {
public:
    NodeObjects(ConfigClient& client, const NodeIdentity& node, const ConfigurationKey* key)
        : client_(client), node_(node), key_(key)
    {
    }

    /// Every object of @p kind, a page at a time.
    ConfigError list(ObjectType kind, std::vector<ObjectEntry>& out);
    ConfigError find(ObjectType kind, const std::string& name, uint32_t& id);
    ConfigError info(uint32_t id, ObjectDetails& out);
    ConfigError statistics(NodeStatistics& out);

private:
    ConfigClient& client_;
    const NodeIdentity& node_;
    const ConfigurationKey* key_;
};

/// What CreateObject makes; the fields its kind does not use stay as they are.
struct ObjectSpec {
    ObjectType kind = ObjectType::Semaphore;
    std::string name;
    uint8_t visibility = 0;      ///< 0 local, 1 regional, 2 global.
    uint32_t initialCount = 1;   ///< Semaphores.
    bool counting = false;       ///< Semaphores.
    bool inheritance = false;    ///< Binary semaphores.
    bool fifo = false;           ///< Semaphores' waiters, ports' messages.
};

/// What CreateTask starts.
struct TaskSpec {
    std::string entry; ///< The image's entry point: a task its application declares.
    std::string name;
    uint8_t priority = 16;
    uint32_t stackSize = 4096;
    uint32_t argument = 0;
};

/// The changes, each authenticated under @p key.
class NodeChanges {
public:
    NodeChanges(ConfigClient& client, const NodeIdentity& node, const ConfigurationKey& key)
        : client_(client), node_(node), key_(key)
    {
    }

    /// Not asked again on silence (a lost reply may hide a task made).
    ConfigError createTask(const TaskSpec& spec, uint32_t& id);
    /// StartTask, StopTask, KillTask or DeleteObject on @p id.
    ConfigError onObject(sei::SeiCommand command, uint32_t id);
    /// Not asked again on silence.
    ConfigError createObject(const ObjectSpec& spec, uint32_t& id);
    /// Not asked again on silence (the slots would be added twice).
    ConfigError addObjects(ObjectType kind, uint16_t count);
    /// The whole configuration record: the sequence written.
    ConfigError setConfiguration(const NodeConfiguration& configuration, uint32_t& sequence);

private:
    ConfigClient& client_;
    const NodeIdentity& node_;
    const ConfigurationKey& key_;
};

} // namespace hostconfig
