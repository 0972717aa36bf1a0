#include <hostconfig/NodeObjects.hpp>

#include <dcos/Status.hpp>

#include <fmt/core.h>

#include <cstdlib>

namespace hostconfig {

namespace {

using sei::SeiCommand;
using sei::SeiMessage;

struct KindWord {
    ObjectType kind;
    const char* word;
};

constexpr KindWord kKindWords[] = {
    {ObjectType::Task, "task"},   {ObjectType::Timer, "timer"},        {ObjectType::Device, "device"},
    {ObjectType::BufferPool, "pool"}, {ObjectType::Heap, "heap"},      {ObjectType::MessagePort, "port"},
    {ObjectType::DsmPublisher, "publisher"}, {ObjectType::Semaphore, "semaphore"},
};

} // namespace

const std::vector<ObjectType>& listedKinds()
{
    static const std::vector<ObjectType> kinds = [] {
        std::vector<ObjectType> all;
        for (const KindWord& word : kKindWords) {
            all.push_back(word.kind);
        }
        return all;
    }();
    return kinds;
}

std::string kindName(uint8_t type)
{
    for (const KindWord& word : kKindWords) {
        if (static_cast<uint8_t>(word.kind) == type) {
            return word.word;
        }
    }
    return fmt::format("type-{}", type);
}

std::optional<ObjectType> kindFromName(const std::string& name)
{
    for (const KindWord& word : kKindWords) {
        if (name == word.word) {
            return word.kind;
        }
    }
    return std::nullopt;
}

namespace {

const char* const kVisibilityWords[] = {"local", "regional", "global"};

} // namespace

const char* visibilityName(uint8_t visibility)
{
    return visibility < sizeof kVisibilityWords / sizeof kVisibilityWords[0] ? kVisibilityWords[visibility] : nullptr;
}

std::optional<uint8_t> visibilityFromName(const std::string& name)
{
    for (uint8_t v = 0; v < sizeof kVisibilityWords / sizeof kVisibilityWords[0]; ++v) {
        if (name == kVisibilityWords[v]) {
            return v;
        }
    }
    return std::nullopt;
}

std::string taskStateName(uint8_t state)
{
    static const char* const names[] = {"gone", "spawning", "ready", "executing", "blocked", "suspended",
                                        "terminating"};
    return state < sizeof names / sizeof names[0] ? names[state] : fmt::format("state-{}", state);
}

std::string kernelStatusText(uint8_t status)
{
    if (status > dcos::kLastStatusValue) {
        return fmt::format("kernel status {}", status);
    }
    return dcos::statusName(static_cast<dcos::Status>(status));
}

std::string idText(uint32_t id)
{
    return fmt::format("0x{:08x}", id);
}

std::optional<uint32_t> parseId(const std::string& text)
{
    if (text.empty()) {
        return std::nullopt;
    }
    const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
    const char* digits = text.c_str() + (hex ? 2 : 0);
    char* end = nullptr;
    const unsigned long long value = std::strtoull(digits, &end, hex ? 16 : 10);
    if (end == digits || *end != '\0' || value > 0xFFFFFFFFull || text[0] == '-' || text[0] == '+') {
        return std::nullopt;
    }
    return static_cast<uint32_t>(value);
}

const std::vector<std::string>& figureNames(uint8_t type)
{
    static const std::vector<std::string> none;
    static const std::vector<std::string> task = {"base_priority", "priority", "stack_size", "stack_used",
                                                  "execution_period_ns", "deadline_period_ns", "profile_samples",
                                                  "profile_min_ns", "profile_max_ns", "profile_total_ns"};
    static const std::vector<std::string> semaphore = {"count", "holder", "settings"};
    static const std::vector<std::string> port = {"order_fifo", "queued", "level_bits", "receiver_waiting"};
    static const std::vector<std::string> pool = {"buffer_size", "buffers", "free", "low_water", "allocations",
                                                  "failed_allocations"};
    static const std::vector<std::string> heap = {"heap_bytes", "free_bytes", "used_bytes", "allocated_segments",
                                                  "free_segments", "largest_free_segment"};
    static const std::vector<std::string> publisher = {"data_id", "page_low", "page_high"};
    switch (static_cast<ObjectType>(type)) {
    case ObjectType::Task: return task;
    case ObjectType::Semaphore: return semaphore;
    case ObjectType::MessagePort: return port;
    case ObjectType::BufferPool: return pool;
    case ObjectType::Heap: return heap;
    case ObjectType::DsmPublisher: return publisher;
    default: return none;
    }
}

uint64_t ObjectDetails::figure(const std::string& wanted) const
{
    for (const auto& [name, value] : figures) {
        if (name == wanted) {
            return value;
        }
    }
    return 0;
}

ConfigError NodeObjects::list(ObjectType kind, std::vector<ObjectEntry>& out)
{
    out.clear();
    SeiMessage request = requestOf(SeiCommand::ListObjects);
    request.objectType = static_cast<uint8_t>(kind);
    request.first = 0;
    // A table has at most 4,096 slots, so at most 512 pages: a node that
    // never says the end cannot keep the tool asking.
    for (int page = 0; page < 4096 / static_cast<int>(sei::kSeiMaxListEntries) + 1; ++page) {
        SeiMessage reply;
        if (const ConfigError error = client_.query(node_, key_, request, reply)) {
            return error;
        }
        for (size_t i = 0; i < reply.entryCount; ++i) {
            ObjectEntry entry;
            entry.type = request.objectType;
            entry.id = reply.entries[i].id;
            entry.owner = reply.entries[i].owner;
            entry.name.assign(reply.entries[i].name, reply.entries[i].nameLength);
            out.push_back(entry);
        }
        if (reply.next == sei::kSeiListEnd) {
            return {};
        }
        if (reply.next <= request.first) {
            ConfigError error;
            error.kind = ConfigError::Kind::Unexpected;
            error.why = fmt::format("the node's listing went back from slot {} to {}", request.first, reply.next);
            return error;
        }
        request.first = reply.next;
    }
    ConfigError error;
    error.kind = ConfigError::Kind::Unexpected;
    error.why = "the node's listing did not end";
    return error;
}

ConfigError NodeObjects::find(ObjectType kind, const std::string& name, uint32_t& id)
{
    SeiMessage request = requestOf(SeiCommand::FindObject);
    request.objectType = static_cast<uint8_t>(kind);
    request.name = name.data();
    request.nameLength = static_cast<uint8_t>(name.size());
    SeiMessage reply;
    const ConfigError error = client_.query(node_, key_, request, reply);
    if (!error) {
        id = reply.objectId;
    }
    return error;
}

ConfigError NodeObjects::info(uint32_t id, ObjectDetails& out)
{
    SeiMessage request = requestOf(SeiCommand::ObjectInfo);
    request.objectId = id;
    SeiMessage reply;
    if (const ConfigError error = client_.query(node_, key_, request, reply)) {
        return error;
    }
    out = ObjectDetails{};
    out.type = reply.objectType;
    out.id = id;
    out.state = reply.state;
    out.visibility = reply.visibility;
    out.owner = reply.owner;
    out.name.assign(reply.name != nullptr ? reply.name : "", reply.nameLength);
    const std::vector<std::string>& names = figureNames(reply.objectType);
    for (size_t i = 0; i < reply.valueCount; ++i) {
        out.figures.emplace_back(i < names.size() ? names[i] : fmt::format("figure_{}", i), reply.values[i]);
    }
    return {};
}

ConfigError NodeObjects::statistics(NodeStatistics& out)
{
    SeiMessage reply;
    if (const ConfigError error = client_.query(node_, key_, requestOf(SeiCommand::NodeStatistics), reply)) {
        return error;
    }
    out = NodeStatistics{};
    out.uptimeNs = reply.uptimeNs;
    out.taskSwitches = reply.taskSwitches;
    out.stackFree = reply.stackFree;
    for (size_t i = 0; i < reply.tableCount; ++i) {
        out.tables.push_back({reply.tables[i].type, reply.tables[i].used, reply.tables[i].capacity});
    }
    return {};
}

ConfigError NodeChanges::createTask(const TaskSpec& spec, uint32_t& id)
{
    SeiMessage request = requestOf(SeiCommand::CreateTask);
    request.text = spec.entry.data();
    request.textLength = static_cast<uint8_t>(spec.entry.size());
    request.name = spec.name.data();
    request.nameLength = static_cast<uint8_t>(spec.name.size());
    request.priority = spec.priority;
    request.stackSize = spec.stackSize;
    request.argument = spec.argument;
    SeiMessage reply;
    const ConfigError error = client_.change(node_, key_, request, reply, true);
    if (!error) {
        id = reply.objectId;
    }
    return error;
}

ConfigError NodeChanges::onObject(SeiCommand command, uint32_t id)
{
    SeiMessage request = requestOf(command);
    request.objectId = id;
    SeiMessage reply;
    // Start and stop mean the same done twice; a kill or delete done twice
    // is said as a stale id, never done to another object.
    return client_.change(node_, key_, request, reply, false);
}

ConfigError NodeChanges::createObject(const ObjectSpec& spec, uint32_t& id)
{
    SeiMessage request = requestOf(SeiCommand::CreateObject);
    request.objectType = static_cast<uint8_t>(spec.kind);
    request.name = spec.name.data();
    request.nameLength = static_cast<uint8_t>(spec.name.size());
    request.visibility = spec.visibility;
    if (spec.kind == ObjectType::Semaphore) {
        request.parameters[0] = spec.initialCount;
        request.parameters[1] = (spec.counting ? sei::kSeiSemaphoreCounting : 0) |
                                (spec.inheritance ? sei::kSeiSemaphoreInheritance : 0) |
                                (spec.fifo ? sei::kSeiSemaphoreFifo : 0);
    } else if (spec.kind == ObjectType::MessagePort) {
        request.parameters[0] = spec.fifo ? 1 : 0;
    }
    SeiMessage reply;
    const ConfigError error = client_.change(node_, key_, request, reply, true);
    if (!error) {
        id = reply.objectId;
    }
    return error;
}

ConfigError NodeChanges::addObjects(ObjectType kind, uint16_t count)
{
    SeiMessage request = requestOf(SeiCommand::AddObjects);
    request.objectType = static_cast<uint8_t>(kind);
    request.count = count;
    SeiMessage reply;
    return client_.change(node_, key_, request, reply, true);
}

ConfigError NodeChanges::setConfiguration(const NodeConfiguration& configuration, uint32_t& sequence)
{
    SeiMessage request = requestOf(SeiCommand::SetConfiguration);
    request.nodeId = configuration.nodeId;
    request.bitRate = configuration.bitRate;
    request.flags = configuration.flags;
    request.lockoutSeconds = configuration.lockoutSeconds;
    request.text = configuration.commandLine.data();
    request.textLength = static_cast<uint8_t>(configuration.commandLine.size());
    SeiMessage reply;
    const ConfigError error = client_.change(node_, key_, request, reply, false);
    if (!error) {
        sequence = reply.sequence;
    }
    return error;
}

} // namespace hostconfig
