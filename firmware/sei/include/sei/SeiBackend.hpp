// What the configuration protocol's server (SeiServer) needs of the node it
// runs in: who the node is, its card's configuration, and the writing of
// that configuration. The kernel's service reads and writes the card
// (boot/ConfigurationBlock.hpp, both copies as boot/RecordCopies.hpp says);
// the host tests and the fuzz target keep it in memory.
//
// No call may block for long: the server answers one request at a time,
// and a write of the card is the longest thing it waits for.
#pragma once

#include <sei/SeiMessage.hpp>
#include <sei/SeiResult.hpp>
#include <sei/SeiStatus.hpp>

#include <stdint.h>

namespace sei {

/// Who the node is now, as Identify tells it.
struct SeiIdentity {
    /// The node id the kernel runs with (not the configured one, which
    /// takes effect at the next start).
    uint16_t nodeId = 0;
    /// The CAN node number the node answers as.
    uint8_t canNode = 0;
    /// As in an image header (image::BoardType: 1 isa486).
    uint8_t board = 0;
    /// Set at manufacture; 0 for none (such a node never answers a scan).
    uint32_t serial = 0;
    /// The running firmware's version, NUL-terminated, valid as long as the
    /// backend; at most kSeiMaxText characters are sent.
    const char* versionText = "";
};

/// The card's configuration record, as GetConfiguration tells it.
struct SeiConfiguration {
    uint32_t sequence = 0;
    /// 0: the kernel's default, 1.
    uint16_t nodeId = 0;
    /// In bit/s; 0: CAN is not started at boot.
    uint32_t bitRate = 0;
    /// GetConfiguration needs a MAC.
    bool queriesClosed = false;
    /// The lockout after three wrong MACs (0: 60 s).
    uint16_t lockoutSeconds = 0;
    /// The kernel command line: readConfiguration gives it NUL-terminated
    /// (at most kSeiMaxText characters are sent); writeConfiguration takes
    /// commandLineLength characters, not terminated.
    const char* commandLine = "";
    uint8_t commandLineLength = 0;
};

class SeiBackend {
public:
    virtual SeiIdentity identity() = 0;
    /// The configuration, or CardError. The texts stay valid until the next call.
    virtual SeiResult<SeiConfiguration> readConfiguration() = 0;
    /// Writes @p nodeId (1 to 254, checked by the server) into the
    /// configuration with the next sequence: that sequence, or CardError
    /// with nothing changed.
    virtual SeiResult<uint32_t> writeNodeId(uint16_t nodeId) = 0;
    /// Writes @p bitRate as writeNodeId writes a node id.
    virtual SeiResult<uint32_t> writeBitRate(uint32_t bitRate) = 0;
    /// Whether the node's CAN controller makes @p bitRate (not 0) exactly.
    virtual bool bitRateValid(uint32_t bitRate) = 0;
    /// Writes @p configuration's node id, bit rate, closed queries, lockout
    /// and command line (checked by the server) as the next record, keeping
    /// the key and serial number: that sequence, or CardError.
    virtual SeiResult<uint32_t> writeConfiguration(const SeiConfiguration& configuration) = 0;
    /// Whether the node's queries are closed now (the configuration's flag
    /// as last read or written), without reading the card.
    virtual bool queriesClosed() = 0;
    /// ActivateBitRate: in @p delayMs, the node switches its CAN controller
    /// to the configured bit rate if it runs at another one.
    virtual void activateBitRate(uint16_t delayMs, uint64_t nowNs) = 0;

    // The management commands (seed 7.14, 4.3.4). Each returns the kernel's
    // dcos::Status as its value (0, Ok, or why the kernel refused), which
    // the server sends back with KernelRefused, and fills in the reply's
    // fields on Ok. Names written into the reply stay valid until the
    // backend's next call.

    /// ListObjects: up to kSeiMaxListEntries objects of @p type from table
    /// index @p first on (entries, entryCount, next).
    virtual uint8_t listObjects(uint8_t type, uint16_t first, SeiMessage& reply) = 0;
    /// FindObject: the id of the local object of @p type named so.
    virtual uint8_t findObject(uint8_t type, const char* name, uint8_t length, uint32_t& id) = 0;
    /// ObjectInfo: objectType, state, owner, name and the type's values.
    virtual uint8_t objectInfo(uint32_t id, SeiMessage& reply) = 0;
    /// NodeStatistics: uptimeNs, taskSwitches, stackFree, tables.
    virtual uint8_t nodeStatistics(SeiMessage& reply) = 0;
    /// CreateTask: a task named request.name running the image's entry
    /// point request.text, at request.priority with request.stackSize bytes
    /// of stack and request.argument.
    virtual uint8_t createTask(const SeiMessage& request, uint32_t& id) = 0;
    virtual uint8_t startTask(uint32_t id) = 0;
    virtual uint8_t stopTask(uint32_t id) = 0;
    virtual uint8_t killTask(uint32_t id) = 0;
    /// CreateObject: request.objectType, name, visibility and parameters.
    virtual uint8_t createObject(const SeiMessage& request, uint32_t& id) = 0;
    virtual uint8_t deleteObject(uint32_t id) = 0;
    virtual uint8_t addObjects(uint8_t type, uint16_t count) = 0;
    /// Monitor: starts, renews or (lease 0) stops the stream to the host
    /// that asked.
    virtual uint8_t monitor(const SeiMessage& request, uint64_t nowNs) = 0;

    /// An authenticated Restart is taken: whatever must be done before the
    /// node goes down (the reply is sent first, then the caller restarts
    /// the node: SeiServer::restartRequested). Anything but Ok refuses the
    /// Restart with that status.
    virtual SeiStatus prepareRestart() = 0;

protected:
    ~SeiBackend() = default;
};

} // namespace sei
