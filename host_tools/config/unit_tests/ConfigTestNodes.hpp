// What dcos-config's unit tests share: nodes in memory that run the
// protocol's own server (sei::SeiServer, with its authenticator), and a
// ConfigLink that carries the tool's requests to them as a CAN bus would:
// to a node's own number, or to the broadcast address, where every node
// takes the scanning commands and only the selected one the others.
#pragma once

#include <hostconfig/ConfigLink.hpp>
#include <hostconfig/ConfigRequest.hpp>

#include <sei/SeiAuthenticator.hpp>
#include <sei/SeiBackend.hpp>
#include <sei/SeiMessage.hpp>
#include <sei/SeiServer.hpp>

#include "../../../firmware/sei/unit_tests/SeiTestSupport.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace config_test {

using hostconfig::Bytes;
using hostconfig::ConfigurationKey;
using hostconfig::LinkError;

constexpr uint64_t kMs = 1000000;
constexpr uint8_t kBroadcast = 255;

/// A key whose bytes are @p first, @p first + 1, ...
inline ConfigurationKey keyOf(uint8_t first)
{
    ConfigurationKey key{};
    for (size_t i = 0; i < key.size(); ++i) {
        key[i] = static_cast<uint8_t>(first + i);
    }
    return key;
}

/// A node's identity, card and objects in memory: the protocol's own tests'.
using MemoryBackend = sei_test::MemoryBackend;

/// A whole node: backend, authenticator (with @p key, or none) and server.
struct MemoryNode {
    MemoryNode(uint32_t serial, uint8_t canNode, std::optional<ConfigurationKey> key, bool queriesClosed = false)
        : backend(backendFor(serial, canNode, queriesClosed)),
          authenticator(key ? key->data() : nullptr, canNode, serial, 0, reinterpret_cast<const uint8_t*>(&serial),
                        sizeof serial),
          server(backend, authenticator)
    {
    }

    static MemoryBackend backendFor(uint32_t serial, uint8_t canNode, bool queriesClosed)
    {
        MemoryBackend backend;
        backend.id.nodeId = canNode;
        backend.id.canNode = canNode;
        backend.id.board = 1;
        backend.id.serial = serial;
        backend.id.versionText = "1.0.0";
        backend.configuration.sequence = 7;
        backend.configuration.nodeId = canNode;
        backend.configuration.bitRate = 250000;
        backend.configuration.queriesClosed = queriesClosed;
        backend.commandLine = "can0=250000";
        return backend;
    }

    /// One request, as the node's CAN service hands it over; the reply, or
    /// nothing when the node keeps silent.
    std::optional<Bytes> take(const Bytes& request, uint64_t nowNs)
    {
        Bytes reply(sei::kSeiMaxMessage);
        reply.resize(server.handle(request.data(), request.size(), reply.data(), reply.size(), nowNs));
        if (reply.empty()) {
            return std::nullopt;
        }
        return reply;
    }

    MemoryBackend backend;
    sei::SeiAuthenticator authenticator;
    sei::SeiServer server;
};

/// A bus of memory nodes as one link sees it: on @p address (a node's CAN
/// node number, or 255).
class MemoryBus final : public hostconfig::ConfigLink {
public:
    MemoryBus(std::vector<MemoryNode*> nodes, uint8_t address) : nodes_(std::move(nodes)), address_(address) {}

    LinkError exchange(const Bytes& request, sei::SeiCommand command, Bytes& reply, std::chrono::milliseconds,
                       std::string& why) override
    {
        nowNs += kMs;
        requests.push_back(request);
        const bool scanning = !request.empty() && (request[0] == static_cast<uint8_t>(sei::SeiCommand::ProbeSerial) ||
                                                   request[0] == static_cast<uint8_t>(sei::SeiCommand::Select) ||
                                                   request[0] == static_cast<uint8_t>(sei::SeiCommand::Deselect));
        std::optional<Bytes> answer;
        for (MemoryNode* node : nodes_) {
            const bool takes = address_ == kBroadcast ? scanning || node->server.selected()
                                                      : node->backend.id.canNode == address_;
            if (!takes) {
                continue;
            }
            std::optional<Bytes> own = node->take(request, nowNs);
            sei::SeiMessage decoded;
            if (own && !answer && hostconfig::answers(command, own->data(), own->size(), decoded)) {
                answer = own;
            }
        }
        // A reply lost on the way back: the node did what it was asked.
        if (answer && dropReplies > 0 && request[0] == static_cast<uint8_t>(dropCommand)) {
            --dropReplies;
            answer.reset();
        }
        if (!answer) {
            why = "no reply";
            return LinkError::Silent;
        }
        reply = *answer;
        return LinkError::None;
    }

    LinkError probe(uint8_t bits, uint32_t value, bool& answered, std::string&) override
    {
        nowNs += 50 * kMs;
        ++probes;
        sei::SeiMessage request;
        request.command = sei::SeiCommand::ProbeSerial;
        request.probeBits = bits;
        request.probeValue = value;
        const Bytes bytes = hostconfig::encodeRequest(request);
        answered = false;
        for (MemoryNode* node : nodes_) {
            answered = node->take(bytes, nowNs).has_value() || answered;
        }
        return LinkError::None;
    }

    LinkError announce(const Bytes& bytes, std::string&) override
    {
        deselects += !bytes.empty() && bytes[0] == static_cast<uint8_t>(sei::SeiCommand::Deselect);
        announced.push_back(bytes);
        for (MemoryNode* node : nodes_) {
            node->take(bytes, nowNs);
        }
        return LinkError::None;
    }

    /// How many of the requests sent were of @p command.
    unsigned sent(sei::SeiCommand command) const
    {
        unsigned count = 0;
        for (const Bytes& request : requests) {
            count += !request.empty() && request[0] == static_cast<uint8_t>(command) ? 1 : 0;
        }
        return count;
    }

    uint64_t nowNs = 1000 * kMs;
    /// Replies to requests of dropCommand still to be lost.
    unsigned dropReplies = 0;
    sei::SeiCommand dropCommand = sei::SeiCommand::Identify;
    std::vector<Bytes> requests;
    unsigned probes = 0;
    unsigned deselects = 0;
    std::vector<Bytes> announced;

private:
    std::vector<MemoryNode*> nodes_;
    uint8_t address_;
};

} // namespace config_test
