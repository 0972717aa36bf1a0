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

    SeiMessage ask(const SeiMessage& message) { return decode(raw(encoded(message))); }

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
    SeiMessage askSigned(const SeiMessage& message) { return decode(raw(signedBytes(message))); }

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
};

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
