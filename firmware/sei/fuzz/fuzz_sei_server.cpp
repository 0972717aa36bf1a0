// Fuzz target: the node's side of the configuration protocol
// (docs/protocols/config.md), which takes every request a host, or
// anything else on the bus, sends to a node: SeiServer directly, and
// CanSeiServer with its connections and its part in scans.
//
// The input's first byte sets the node up: bit 0 it holds a key, bit 1
// its queries are closed, bit 2 its card fails, bit 3 it has no serial
// number. The rest is a script of events, each starting with one byte:
//   0..3   a CAN frame: then one byte that picks its identifier (the node's
//          connection at priority 31 or 3, the broadcast address, another
//          node, another message type, a standard frame), one byte of
//          length (taken modulo 9) and that many data bytes
//   4      the node's first unconfirmed frame is confirmed
//   5      time passes: one byte, in units of 10 ms
//   6      a request to the server: one byte of length (modulo 32), then
//          that many bytes
//   7      the same, but its last 16 bytes are replaced by the right MAC
//          under the node's key and the last challenge a request of kind 6
//          or 7 drew (what an authenticated host sends)
//   8      time passes: one byte, in seconds (challenges go stale, lockouts end)
//   other  a poll at the present time
// Checks: every reply decodes and answers its request's code (or is the
// unreadable request's); every frame the CAN server asks to send is an
// extended Configuration frame to a host, from the node's number, or from
// 255 only as a scan's single-frame answer (or the refusal of a malformed
// broadcast command: Deselect, ActivateBitRate) or while the node is selected;
// nothing is written to the card and no restart is asked before a request
// of kind 7 (no MAC a fuzzer makes up verifies); a lockout never says more
// seconds than configured; the next deadline never lies in the past after
// a poll.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <sei/CanSeiServer.hpp>
#include <sei/SeiAuthenticator.hpp>
#include <sei/SeiBackend.hpp>
#include <sei/SeiMessage.hpp>
#include <sei/SeiServer.hpp>

#include <can/IsoTpPci.hpp>
#include <can/MessageIdentifier.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace {

constexpr uint8_t kNode = 9;
constexpr uint16_t kLockoutSeconds = 5;
constexpr uint32_t kSerial = 0x5EED0001;
constexpr uint8_t kKey[sei::kSeiKeySize] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16,
                                            17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32};
constexpr size_t kMaxRequest = 32;

class FuzzBackend final : public sei::SeiBackend {
public:
    sei::SeiIdentity identity() override
    {
        sei::SeiIdentity id;
        id.nodeId = kNode;
        id.canNode = kNode;
        id.board = 1;
        id.serial = serial;
        id.versionText = "fuzz";
        return id;
    }
    sei::SeiResult<sei::SeiConfiguration> readConfiguration() override
    {
        if (failing) {
            return sei::SeiStatus::CardError;
        }
        sei::SeiConfiguration configuration;
        configuration.sequence = sequence;
        configuration.nodeId = kNode;
        configuration.queriesClosed = queriesClosed_;
        configuration.lockoutSeconds = kLockoutSeconds;
        configuration.commandLine = "can0=125000";
        return configuration;
    }
    sei::SeiResult<uint32_t> writeNodeId(uint16_t nodeId) override
    {
        FUZZ_CHECK(nodeId >= sei::SeiServer::kMinNodeId && nodeId <= sei::SeiServer::kMaxNodeId);
        return write();
    }
    sei::SeiResult<uint32_t> writeBitRate(uint32_t bitRate) override
    {
        FUZZ_CHECK(bitRate != 0 && bitRateValid(bitRate));
        return write();
    }
    bool bitRateValid(uint32_t bitRate) override { return bitRate == 125000 || bitRate == 500000; }
    sei::SeiStatus prepareRestart() override { return failing ? sei::SeiStatus::CardError : sei::SeiStatus::Ok; }
    sei::SeiResult<uint32_t> writeConfiguration(const sei::SeiConfiguration& configuration) override
    {
        FUZZ_CHECK(configuration.nodeId <= sei::SeiServer::kMaxNodeId);
        FUZZ_CHECK(configuration.bitRate != 0 && bitRateValid(configuration.bitRate));
        FUZZ_CHECK(configuration.commandLineLength <= sei::kSeiMaxText);
        return write();
    }
    bool queriesClosed() override { return queriesClosed_; }
    void activateBitRate(uint16_t, uint64_t) override { ++activations; }

    // The management commands: the queries answer with full replies, so
    // their encoding is exercised at its largest; every change counts as a
    // write, which only an authenticated request may make.
    uint8_t listObjects(uint8_t type, uint16_t first, sei::SeiMessage& reply) override
    {
        if (type == 0 || type > 13) {
            return 6; // InvalidArgument
        }
        reply.entryCount = sei::kSeiMaxListEntries;
        for (size_t i = 0; i < reply.entryCount; ++i) {
            reply.entries[i] = {static_cast<uint32_t>((kNode << 16) | (type << 12) | (first + i)), 0,
                                "fifteen-letters", static_cast<uint8_t>(i * 2)};
        }
        reply.next = first < 64 ? static_cast<uint16_t>(first + sei::kSeiMaxListEntries) : sei::kSeiListEnd;
        return 0;
    }
    uint8_t findObject(uint8_t, const char*, uint8_t length, uint32_t& id) override
    {
        id = length;
        return length % 2 == 0 ? 0 : 13; // NotFound
    }
    uint8_t objectInfo(uint32_t id, sei::SeiMessage& reply) override
    {
        reply.objectType = static_cast<uint8_t>((id >> 12) & 0xF);
        reply.name = "fifteen-letters";
        reply.nameLength = 15;
        reply.valueCount = sei::kSeiMaxValues;
        for (size_t i = 0; i < reply.valueCount; ++i) {
            reply.values[i] = ~uint64_t{0} - i;
        }
        return id == 0 ? 1 : 0;
    }
    uint8_t nodeStatistics(sei::SeiMessage& reply) override
    {
        reply.uptimeNs = ~uint64_t{0};
        reply.tableCount = sei::kSeiMaxTables;
        return 0;
    }
    uint8_t createTask(const sei::SeiMessage& request, uint32_t& id) override
    {
        FUZZ_CHECK(request.textLength <= sei::kSeiMaxName && request.nameLength <= sei::kSeiMaxName);
        return change(id);
    }
    uint8_t startTask(uint32_t id) override { return change(id); }
    uint8_t stopTask(uint32_t id) override { return change(id); }
    uint8_t killTask(uint32_t id) override { return change(id); }
    uint8_t createObject(const sei::SeiMessage& request, uint32_t& id) override
    {
        FUZZ_CHECK(request.nameLength <= sei::kSeiMaxName);
        return change(id);
    }
    uint8_t deleteObject(uint32_t id) override { return change(id); }
    uint8_t addObjects(uint8_t, uint16_t count) override
    {
        uint32_t id = count;
        return change(id);
    }
    uint8_t monitor(const sei::SeiMessage& request, uint64_t) override
    {
        FUZZ_CHECK(request.channelCount <= sei::kSeiMaxMonitorChannels);
        for (size_t i = 0; i < request.channelCount; ++i) {
            FUZZ_CHECK(request.channels[i].offset + sei::seiSampleSize(request.channels[i].format) <=
                       sei::kSeiPageSize);
        }
        return 0;
    }

    // A change the node would make: a write; odd ids are refused as the
    // kernel refuses a stale one.
    uint8_t change(uint32_t& id)
    {
        ++writes;
        return id % 2 == 0 ? 0 : 2;
    }

    sei::SeiResult<uint32_t> write()
    {
        if (failing) {
            return sei::SeiStatus::CardError;
        }
        ++writes;
        return ++sequence;
    }

    uint32_t serial = kSerial;
    bool queriesClosed_ = false;
    unsigned activations = 0;
    bool failing = false;
    uint32_t sequence = 1;
    unsigned writes = 0;
};

uint32_t identifierFor(uint8_t pick)
{
    using can::MessageIdentifier;
    using can::MessageType;
    const uint8_t host = static_cast<uint8_t>(pick >> 4);
    switch (pick % 8) {
    case 0: return MessageIdentifier::make(31, MessageType::Configuration, kNode, 254).value().encode();
    case 1: return MessageIdentifier::make(3, MessageType::Configuration, kNode, host).value().encode();
    case 2: return MessageIdentifier::make(31, MessageType::Configuration, MessageIdentifier::kBroadcast, 254).value().encode();
    case 3: return MessageIdentifier::make(3, MessageType::Configuration, MessageIdentifier::kBroadcast, host).value().encode();
    case 4: return MessageIdentifier::make(31, MessageType::Configuration, kNode + 1, 254).value().encode();
    case 5: return MessageIdentifier::make(31, MessageType::Flashing, kNode, 254).value().encode();
    case 6: return pick; // a standard frame
    default: return 0x1F40FEFF; // another node's answer from 255
    }
}

bool isScanAnswer(const can::CanFrame& frame)
{
    if (frame.length() < 2 || frame.data()[0] > can::IsoTpPci::kMaxSingleFrameData) {
        return false;
    }
    const uint8_t code = frame.data()[1];
    return code == (static_cast<uint8_t>(sei::SeiCommand::ProbeSerial) | sei::kSeiReplyBit) ||
           code == (static_cast<uint8_t>(sei::SeiCommand::Select) | sei::kSeiReplyBit) ||
           code == (static_cast<uint8_t>(sei::SeiCommand::Deselect) | sei::kSeiReplyBit) ||
           code == (static_cast<uint8_t>(sei::SeiCommand::ActivateBitRate) | sei::kSeiReplyBit);
}

void checkOutput(const sei::SeiServer& server, const sei::CanSeiServer::Output& output)
{
    if (!output.transmit) {
        return;
    }
    FUZZ_CHECK(output.frame.format() == can::IdFormat::Extended);
    const uint32_t id = output.frame.id();
    FUZZ_CHECK(((id >> can::MessageIdentifier::kTypeShift) & 0xFF) ==
               static_cast<uint8_t>(can::MessageType::Configuration));
    const uint8_t destination = static_cast<uint8_t>(id >> can::MessageIdentifier::kDestinationShift);
    const uint8_t source = static_cast<uint8_t>(id >> can::MessageIdentifier::kSourceShift);
    FUZZ_CHECK(destination != can::MessageIdentifier::kBroadcast);
    FUZZ_CHECK(source == kNode || source == can::MessageIdentifier::kBroadcast);
    if (source == can::MessageIdentifier::kBroadcast) {
        FUZZ_CHECK(isScanAnswer(output.frame) || server.selected());
    }
    FUZZ_CHECK(output.frame.length() >= 1 && output.frame.length() <= 8);
}

// A reply of the server: it decodes, and answers the request's code.
void checkReply(const uint8_t* request, size_t length, const uint8_t* reply, size_t replyLength)
{
    if (replyLength == 0) {
        return;
    }
    FUZZ_CHECK(replyLength <= sei::kSeiMaxMessage);
    sei::SeiMessage decoded;
    FUZZ_CHECK(sei::SeiMessage::decode(reply, replyLength, decoded));
    if (decoded.kind == sei::SeiMessageKind::Unreadable) {
        FUZZ_CHECK(length == 0 || !sei::isSeiCommand(request[0]));
        return;
    }
    FUZZ_CHECK(decoded.kind == sei::SeiMessageKind::Reply);
    FUZZ_CHECK(length != 0 && static_cast<uint8_t>(decoded.command) == request[0]);
    if (decoded.status == sei::SeiStatus::LockedOut) {
        FUZZ_CHECK(decoded.lockoutSecondsLeft >= 1 && decoded.lockoutSecondsLeft <= kLockoutSeconds);
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size == 0) {
        return 0;
    }
    const uint8_t setup = data[0];
    const bool hasKey = (setup & 1) != 0;
    FuzzBackend backend;
    backend.queriesClosed_ = (setup & 2) != 0;
    backend.failing = (setup & 4) != 0;
    backend.serial = (setup & 8) != 0 ? 0 : kSerial;
    sei::SeiAuthenticator authenticator(hasKey ? kKey : nullptr, kNode, backend.serial, kLockoutSeconds,
                                        reinterpret_cast<const uint8_t*>("fuzz"), 4);
    sei::SeiServer server(backend, authenticator);
    sei::CanSeiServer can(server, kNode);
    uint8_t challenge[sei::kSeiChallengeSize] = {};
    bool signedSent = false;
    uint64_t now = 0;
    size_t i = 1;
    while (i < size) {
        const uint8_t kind = data[i++];
        if (kind <= 3) {
            if (i + 2 > size) {
                break;
            }
            const uint8_t pick = data[i++];
            uint8_t length = static_cast<uint8_t>(data[i++] % 9);
            if (length > size - i) {
                length = static_cast<uint8_t>(size - i);
            }
            const can::IdFormat format = pick % 8 == 6 ? can::IdFormat::Standard : can::IdFormat::Extended;
            const can::LinkResult<can::CanFrame> frame =
                can::CanFrame::makeData(identifierFor(pick) & can::CanFrame::maxId(format), format, data + i, length);
            i += length;
            if (frame.ok()) {
                checkOutput(server, can.onFrame(frame.value(), now));
            }
        } else if (kind == 4) {
            checkOutput(server, can.onTransmitConfirmed(now));
        } else if (kind == 5 || kind == 8) {
            if (i < size) {
                now += uint64_t{data[i++]} * (kind == 5 ? 10000000ull : 1000000000ull);
            }
        } else if (kind == 6 || kind == 7) {
            if (i >= size) {
                break;
            }
            size_t length = data[i++] % kMaxRequest;
            if (length > size - i) {
                length = size - i;
            }
            uint8_t request[kMaxRequest] = {};
            std::memcpy(request, data + i, length);
            i += length;
            if (kind == 7 && length > sei::kSeiMacSize) {
                uint8_t mac[sei::kSeiMacSize];
                sei::seiMac(kKey, kNode, backend.serial, challenge, request, length - sei::kSeiMacSize, mac);
                std::memcpy(request + length - sei::kSeiMacSize, mac, sizeof mac);
                signedSent = true;
            }
            uint8_t reply[sei::kSeiMaxMessage];
            const size_t replyLength = server.handle(request, length, reply, sizeof reply, now);
            checkReply(request, length, reply, replyLength);
            if (replyLength == 2 + sei::kSeiChallengeSize &&
                reply[0] == (static_cast<uint8_t>(sei::SeiCommand::Challenge) | sei::kSeiReplyBit)) {
                std::memcpy(challenge, reply + 2, sizeof challenge);
            }
        } else {
            const sei::CanSeiServer::Output output = can.poll(now);
            checkOutput(server, output);
            // One frame per poll: a connection not polled yet may still be due.
            if (!output.transmit) {
                FUZZ_CHECK(can.nextDeadlineNs() > now);
            }
        }
        FUZZ_CHECK(backend.writes == 0 || signedSent);
        FUZZ_CHECK(!server.restartRequested() || signedSent);
        FUZZ_CHECK(!can.restartDue() || server.restartRequested());
        FUZZ_CHECK(authenticator.lockoutSecondsLeft(now) <= kLockoutSeconds);
    }
    return 0;
}
