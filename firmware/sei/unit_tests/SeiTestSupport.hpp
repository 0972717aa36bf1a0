// What the configuration protocol's host tests share: a node's backend in
// memory (its identity and its card's configuration, a card that can fail),
// a whole node (backend, authenticator, server), and a host side that asks
// a node message by message and signs what needs a MAC, as dcos-config will.
#pragma once

#include <sei/SeiAuthenticator.hpp>
#include <sei/SeiBackend.hpp>
#include <sei/SeiMessage.hpp>
#include <sei/SeiServer.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace sei_test {

using sei::SeiCommand;
using sei::SeiMessage;
using sei::SeiMessageKind;
using sei::SeiStatus;

using Bytes = std::vector<uint8_t>;
using Key = std::array<uint8_t, sei::kSeiKeySize>;

constexpr uint64_t kMs = 1000000;
constexpr uint64_t kSecond = 1000 * kMs;

/// A key whose bytes are @p first, @p first + 1, ...
inline Key keyOf(uint8_t first)
{
    Key key;
    for (size_t i = 0; i < key.size(); ++i) {
        key[i] = static_cast<uint8_t>(first + i);
    }
    return key;
}

inline Bytes encoded(const SeiMessage& message)
{
    Bytes bytes(sei::kSeiMaxMessage);
    const size_t length = message.encode(bytes.data(), bytes.size());
    EXPECT_NE(length, 0u);
    bytes.resize(length);
    return bytes;
}

inline SeiMessage request(SeiCommand command)
{
    SeiMessage m;
    m.kind = SeiMessageKind::Request;
    m.command = command;
    return m;
}

/// A node's identity and card in memory.
class MemoryBackend final : public sei::SeiBackend {
public:
    MemoryBackend()
    {
        id.nodeId = 5;
        id.canNode = 5;
        id.board = 1;
        id.serial = 0x12345678;
        id.versionText = "0.1.0";
        configuration.sequence = 7;
        configuration.nodeId = 5;
        configuration.bitRate = 250000;
        configuration.lockoutSeconds = 0;
    }

    sei::SeiIdentity identity() override { return id; }
    sei::SeiResult<sei::SeiConfiguration> readConfiguration() override
    {
        if (failing) {
            return SeiStatus::CardError;
        }
        sei::SeiConfiguration copy = configuration;
        copy.commandLine = commandLine.c_str();
        return copy;
    }
    sei::SeiResult<uint32_t> writeNodeId(uint16_t nodeId) override
    {
        if (failing) {
            return SeiStatus::CardError;
        }
        ++writes;
        configuration.nodeId = nodeId;
        return ++configuration.sequence;
    }
    sei::SeiResult<uint32_t> writeBitRate(uint32_t bitRate) override
    {
        if (failing) {
            return SeiStatus::CardError;
        }
        ++writes;
        configuration.bitRate = bitRate;
        return ++configuration.sequence;
    }
    bool bitRateValid(uint32_t bitRate) override { return validRates.count(bitRate) != 0; }
    sei::SeiStatus prepareRestart() override { return restartStatus; }
    sei::SeiResult<uint32_t> writeConfiguration(const sei::SeiConfiguration& written) override
    {
        if (failing) {
            return SeiStatus::CardError;
        }
        ++writes;
        const uint32_t sequence = configuration.sequence;
        configuration = written;
        configuration.sequence = sequence + 1;
        commandLine.assign(written.commandLine, written.commandLineLength);
        return configuration.sequence;
    }
    bool queriesClosed() override { return configuration.queriesClosed; }
    void activateBitRate(uint16_t delayMs, uint64_t nowNs) override
    {
        activations.push_back({delayMs, nowNs});
    }

    // The kernel's statuses (dcos/Status.hpp), as numbers on the wire.
    static constexpr uint8_t kInvalidId = 1, kWrongType = 3, kTableFull = 4, kInvalidArgument = 6,
                             kNotFound = 13, kAlreadyExists = 14, kNotSupported = 18;
    // Object types (dcos/ObjectId.hpp).
    static constexpr uint8_t kTask = 1, kTimer = 3, kDevice = 4, kPool = 5, kHeap = 6, kPort = 7, kPublisher = 8,
                             kSemaphore = 10;

    /// An object in the node's tables; its id is (node 5, type, index).
    struct Object {
        uint8_t type = 0;
        uint32_t owner = 0;
        std::string name;
        uint8_t state = 2; // dcos::TaskState::Ready
        uint8_t visibility = 0;
        uint8_t priority = 0;
        uint32_t stackSize = 0;
    };

    static uint32_t idOf(uint8_t type, uint16_t index) { return (5u << 16) | (uint32_t{type} << 12) | index; }

    uint8_t listObjects(uint8_t type, uint16_t first, SeiMessage& reply) override
    {
        if (capacity.count(type) == 0) {
            return kInvalidArgument;
        }
        reply.entryCount = 0;
        reply.next = sei::kSeiListEnd;
        listed.clear();
        for (const auto& [object, value] : objects) {
            const uint16_t index = static_cast<uint16_t>(object & 0xFFF);
            if (value.type != type || index < first) {
                continue;
            }
            if (reply.entryCount == sei::kSeiMaxListEntries) {
                reply.next = index;
                break;
            }
            listed.push_back(value.name);
            sei::SeiObjectEntry& entry = reply.entries[reply.entryCount++];
            entry.id = object;
            entry.owner = value.owner;
            entry.nameLength = static_cast<uint8_t>(value.name.size());
        }
        for (size_t i = 0; i < reply.entryCount; ++i) {
            reply.entries[i].name = listed[i].c_str();
        }
        return 0;
    }
    uint8_t findObject(uint8_t type, const char* name, uint8_t length, uint32_t& found) override
    {
        const std::string wanted(name, length);
        for (const auto& [object, value] : objects) {
            if (value.type == type && value.name == wanted) {
                found = object;
                return 0;
            }
        }
        return capacity.count(type) == 0 ? kInvalidArgument : kNotFound;
    }
    uint8_t objectInfo(uint32_t object, SeiMessage& reply) override
    {
        const auto it = objects.find(object);
        if (it == objects.end()) {
            return kInvalidId;
        }
        reply.objectType = it->second.type;
        reply.state = it->second.type == kTask ? it->second.state : 0;
        reply.visibility = it->second.visibility;
        reply.owner = it->second.owner;
        reply.name = it->second.name.c_str();
        reply.nameLength = static_cast<uint8_t>(it->second.name.size());
        // As the node's: base priority, priority, stack size.
        reply.valueCount = it->second.type == kTask ? 3 : 0;
        reply.values[0] = it->second.priority;
        reply.values[1] = it->second.priority;
        reply.values[2] = it->second.stackSize;
        return 0;
    }
    uint8_t nodeStatistics(SeiMessage& reply) override
    {
        reply.uptimeNs = 123456789012ull;
        reply.taskSwitches = 4242;
        reply.stackFree = 65536;
        reply.tableCount = 0;
        for (const auto& [type, slots] : capacity) {
            sei::SeiTableUsage& usage = reply.tables[reply.tableCount++];
            usage.type = type;
            usage.used = static_cast<uint16_t>(countOf(type));
            usage.capacity = static_cast<uint16_t>(slots);
        }
        return 0;
    }
    uint8_t createTask(const SeiMessage& request, uint32_t& created) override
    {
        const std::string entry(request.text, request.textLength);
        if (entries.count(entry) == 0) {
            return kNotFound;
        }
        if (request.priority > 31 || request.stackSize < 1024) {
            return kInvalidArgument;
        }
        Object task;
        task.type = kTask;
        task.name.assign(request.name, request.nameLength);
        task.priority = request.priority;
        task.stackSize = request.stackSize;
        return add(task, created);
    }
    uint8_t startTask(uint32_t task) override { return setState(task, 2); }
    uint8_t stopTask(uint32_t task) override { return setState(task, 5); }
    uint8_t killTask(uint32_t task) override
    {
        const uint8_t checked = checkTask(task);
        if (checked == 0) {
            objects.erase(task);
        }
        return checked;
    }
    uint8_t createObject(const SeiMessage& request, uint32_t& created) override
    {
        if (request.objectType != kSemaphore && request.objectType != kPort && request.objectType != kPublisher) {
            return request.objectType == kPool || request.objectType == kHeap ? kNotSupported : kInvalidArgument;
        }
        Object object;
        object.type = request.objectType;
        object.name.assign(request.name, request.nameLength);
        object.visibility = request.visibility;
        return add(object, created);
    }
    uint8_t deleteObject(uint32_t object) override
    {
        const auto it = objects.find(object);
        if (it == objects.end()) {
            return kInvalidId;
        }
        objects.erase(it);
        return 0;
    }
    uint8_t addObjects(uint8_t type, uint16_t count) override
    {
        if (capacity.count(type) == 0 || capacity[type] + count > 64) {
            return kInvalidArgument;
        }
        capacity[type] += count;
        return 0;
    }
    uint8_t monitor(const SeiMessage& request, uint64_t) override
    {
        for (size_t i = 0; i < request.channelCount; ++i) {
            const auto it = objects.find(request.channels[i].publisher);
            if (it == objects.end()) {
                return kInvalidId;
            }
            if (it->second.type != kPublisher) {
                return kWrongType;
            }
        }
        monitorRequests.push_back(request);
        return 0;
    }

    size_t countOf(uint8_t type) const
    {
        return static_cast<size_t>(std::count_if(objects.begin(), objects.end(),
                                                 [type](const auto& entry) { return entry.second.type == type; }));
    }

    /// Adds @p object with the next index of its type; TableFull or AlreadyExists as the kernel says them.
    uint8_t add(const Object& object, uint32_t& created)
    {
        if (countOf(object.type) >= capacity[object.type]) {
            return kTableFull;
        }
        for (const auto& [other, value] : objects) {
            if (value.type == object.type && !object.name.empty() && value.name == object.name) {
                return kAlreadyExists;
            }
        }
        created = idOf(object.type, nextIndex++);
        objects[created] = object;
        return 0;
    }
    uint8_t checkTask(uint32_t task)
    {
        const auto it = objects.find(task);
        if (it == objects.end()) {
            return ((task >> 12) & 0xF) == kTask ? kInvalidId : kWrongType;
        }
        return it->second.type == kTask ? 0 : kWrongType;
    }
    uint8_t setState(uint32_t task, uint8_t state)
    {
        const uint8_t checked = checkTask(task);
        if (checked == 0) {
            objects[task].state = state;
        }
        return checked;
    }

    std::map<uint32_t, Object> objects;
    std::map<uint8_t, size_t> capacity = {{kTask, 8}, {kTimer, 8}, {kDevice, 8}, {kPool, 4},
                                          {kHeap, 4}, {kPort, 8}, {kPublisher, 8}, {kSemaphore, 8}};
    std::set<std::string> entries = {"sampler", "logger"};
    uint16_t nextIndex = 1;
    std::vector<std::string> listed;
    std::vector<SeiMessage> monitorRequests;
    std::vector<std::pair<uint16_t, uint64_t>> activations;

    sei::SeiIdentity id;
    sei::SeiConfiguration configuration;
    std::string commandLine = "can0=250000 console=com1";
    /// The card cannot be read or written.
    bool failing = false;
    unsigned writes = 0;
    sei::SeiStatus restartStatus = SeiStatus::Ok;
    std::set<uint32_t> validRates = {125000, 250000, 500000, 1000000};
};

/// A node: backend, authenticator and server, with its key (or none).
struct Node {
    explicit Node(std::optional<Key> key = keyOf(0x11), uint32_t serial = 0x12345678, uint16_t lockoutSeconds = 0,
                  bool queriesClosed = false, uint16_t nodeId = 5)
        : nodeKey(key), backend(backendFor(serial, queriesClosed, lockoutSeconds, nodeId)),
          authenticator(key ? key->data() : nullptr, nodeId, serial, lockoutSeconds, seedOf(serial).data(),
                        sizeof serial),
          server(backend, authenticator)
    {
    }

    /// Challenges differ from node to node, as their starts do.
    static std::array<uint8_t, 4> seedOf(uint32_t serial)
    {
        return {static_cast<uint8_t>(serial), static_cast<uint8_t>(serial >> 8), static_cast<uint8_t>(serial >> 16),
                static_cast<uint8_t>(serial >> 24)};
    }

    static MemoryBackend backendFor(uint32_t serial, bool queriesClosed, uint16_t lockoutSeconds, uint16_t nodeId)
    {
        MemoryBackend backend;
        backend.id.serial = serial;
        backend.id.nodeId = nodeId;
        backend.id.canNode = static_cast<uint8_t>(nodeId);
        backend.configuration.nodeId = nodeId;
        backend.configuration.queriesClosed = queriesClosed;
        backend.configuration.lockoutSeconds = lockoutSeconds;
        return backend;
    }

    std::optional<Key> nodeKey;
    MemoryBackend backend;
    sei::SeiAuthenticator authenticator;
    sei::SeiServer server;
};

/// The host's side: asks through a carrier (the server directly, or CAN),
/// keeps the last challenge and signs requests with a key.
class SeiHost {
public:
    /// Sends request bytes and brings back the reply, or nothing.
    using Carrier = std::function<std::optional<Bytes>(const Bytes&)>;

    SeiHost(Carrier carrier, const Key& key, uint16_t nodeId, uint32_t serial)
        : carrier_(std::move(carrier)), key_(key), nodeId_(nodeId), serial_(serial)
    {
    }

    /// The reply's bytes; fails the test when there is none.
    Bytes raw(const Bytes& bytes)
    {
        const std::optional<Bytes> reply = carrier_(bytes);
        EXPECT_TRUE(reply.has_value()) << "no reply";
        return reply.value_or(Bytes{});
    }

    /// The reply's names and text point into the host's last reply: valid
    /// until the next ask.
    SeiMessage ask(const SeiMessage& message)
    {
        last_ = raw(encoded(message));
        return decode(last_);
    }

    static SeiMessage decode(const Bytes& bytes)
    {
        SeiMessage reply;
        EXPECT_TRUE(SeiMessage::decode(bytes.data(), bytes.size(), reply)) << "the reply does not decode";
        return reply;
    }

    /// Asks for a challenge and keeps it.
    SeiMessage challenge()
    {
        const SeiMessage reply = ask(request(SeiCommand::Challenge));
        if (reply.status == SeiStatus::Ok) {
            std::copy(std::begin(reply.challenge), std::end(reply.challenge), challenge_.begin());
        }
        return reply;
    }

    /// @p message's bytes with the MAC under the last challenge.
    Bytes signedBytes(SeiMessage message)
    {
        message.hasMac = true;
        Bytes bytes = encoded(message);
        uint8_t mac[sei::kSeiMacSize];
        const size_t covered = bytes.size() - sei::kSeiMacSize;
        uint8_t key[sei::kSeiKeySize];
        std::copy(key_.begin(), key_.end(), key);
        uint8_t challenge[sei::kSeiChallengeSize];
        std::copy(challenge_.begin(), challenge_.end(), challenge);
        sei::seiMac(key, nodeId_, serial_, challenge, bytes.data(), covered, mac);
        std::copy(std::begin(mac), std::end(mac), bytes.begin() + static_cast<long>(covered));
        return bytes;
    }

    /// Asks @p message signed under the last challenge.
    SeiMessage askSigned(const SeiMessage& message)
    {
        last_ = raw(signedBytes(message));
        return decode(last_);
    }

    /// A new challenge, then @p message signed under it.
    SeiMessage authenticated(const SeiMessage& message)
    {
        EXPECT_EQ(challenge().status, SeiStatus::Ok);
        return askSigned(message);
    }

    void setKey(const Key& key) { key_ = key; }

private:
    Carrier carrier_;
    Key key_;
    uint16_t nodeId_;
    uint32_t serial_;
    std::array<uint8_t, sei::kSeiChallengeSize> challenge_ = {};
    Bytes last_;
};

/// Carries a host's requests straight to @p server at the time @p now holds
/// when each is sent.
inline SeiHost::Carrier serverCarrier(sei::SeiServer& server, const uint64_t& now)
{
    return [&server, &now](const Bytes& bytes) -> std::optional<Bytes> {
        Bytes reply(sei::kSeiMaxMessage);
        const size_t length = server.handle(bytes.data(), bytes.size(), reply.data(), reply.size(), now);
        if (length == 0) {
            return std::nullopt;
        }
        reply.resize(length);
        return reply;
    };
}

inline SeiMessage setNodeId(uint16_t nodeId)
{
    SeiMessage m = request(SeiCommand::SetNodeId);
    m.nodeId = nodeId;
    return m;
}

inline SeiMessage setBitRate(uint32_t bitRate)
{
    SeiMessage m = request(SeiCommand::SetBitRate);
    m.bitRate = bitRate;
    return m;
}

inline SeiMessage probe(uint8_t bits, uint32_t value)
{
    SeiMessage m = request(SeiCommand::ProbeSerial);
    m.probeBits = bits;
    m.probeValue = value;
    return m;
}

inline SeiMessage select(uint32_t serial)
{
    SeiMessage m = request(SeiCommand::Select);
    m.serial = serial;
    return m;
}

} // namespace sei_test
