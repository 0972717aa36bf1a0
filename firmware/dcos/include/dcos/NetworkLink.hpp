// What the network interfaces manager needs of a network driver (seed 7.13):
// send a system message to a physical address, and hand over the messages
// that arrived for this node.
//
// A link is the glue between one local interface of the manager's tables
// and the driver that carries it: sja1000::CanNetworkLink puts a message in
// one extended CAN frame whose identifier is the message's priority, type,
// destination and source (docs/protocols/can.md). A super-user task attaches
// it to an interface with NetworkInterfacesManager::AttachLink, and from
// then on every remote transaction for a node reached over that interface
// goes through it.
//
// The kernel calls Send from the task that makes the request (or from the
// remote agent, for a reply) and Receive from the remote agent's receiver
// task only, after the link posted that task the event it was given in
// Start; the link never blocks.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// The kinds of system message, with the values of the CAN message types
/// (docs/protocols/can.md) so that a CAN link passes them through.
enum class SystemMessageType : uint8_t {
    TimeSync = 0x01, ///< The global time base's Sync, FollowUp and Probe, to the broadcast address (docs/protocols/time.md).
    RemoteReply = 0x10,
    RemoteRequest = 0x11,
    NameQuery = 0x12, ///< A part of a name query, to the broadcast address (docs/protocols/remote-transactions.md).
    RoutedRequest = 0x13, ///< A route header or a request's frame, to a gateway (docs/protocols/remote-transactions.md, "Gateways").
    NodeStarted = 0x14, ///< A node's first message on an interface since it started, to the broadcast address (remote-transactions.md, "A node that starts again").
    DsmPublication = 0x20, ///< A part of a publication, to the broadcast address (docs/protocols/publications.md).
    RelayedPublication = 0x21, ///< A relay header or a publication's frame, from a gateway (publications.md, "Across a gateway").
    Configuration = 0x40, ///< A frame of the configuration protocol (docs/protocols/config.md, "On CAN"), for the system engineering interface agent.
    Monitoring = 0x41, ///< A frame of the stream of samples and console output the agent sends to a host (docs/protocols/monitor.md); nodes send it, never take it.
    Flashing = 0x50, ///< A frame of the flash protocol's ISO-TP connection (docs/protocols/flash.md, "On CAN"), for the system engineering interface agent.
};

/// One system message as a link carries it.
struct SystemMessage {
    /// The sending task's priority, 0 (most urgent) to 31: the bus priority.
    uint8_t priority = 0;
    SystemMessageType type = SystemMessageType::RemoteRequest;
    /// Physical addresses on the link's network (the CAN node numbers). The
    /// source is filled in by Receive; Send puts the link's own address,
    /// unless the source is kBroadcast: then the network's "any node" (on
    /// CAN 255), which the configuration protocol's answers to a scan and
    /// from a selected node carry (docs/protocols/config.md, "Scanning").
    uint32_t destination = 0;
    uint32_t source = 0;
    uint8_t length = 0;
    uint8_t data[8]{};
    /// Send: hand the message back through Receive once it has gone, with
    /// echo set and timeNs the moment it left (the end of its frame on a
    /// bus); the global time base's master learns so when its Sync went. A
    /// link that cannot refuses the Send with NotSupported.
    /// Receive: this is such an echo of the node's own message.
    bool echo = false;
    /// Receive: the uptime (TimerAgent::Uptime) at which the message
    /// arrived, read in the driver's interrupt; 0 from a link that does not
    /// timestamp.
    uint64_t timeNs = 0;
    /// Receive: the instruction counter (arch_x86/InstructionCounter.hpp)
    /// read at the start of the same interrupt; 0 from a link that does not
    /// stamp, or in an image without a counter. The remote agent counts a
    /// transaction's work on each node from it (docs/performance.md).
    uint64_t instructionStamp = 0;
};

class NetworkLink {
public:
    /// The destination of a message for every node on the link's network.
    static constexpr uint32_t kBroadcast = 0xFFFFFFFF;

    /// Begins delivery: post @p receiveEvent to task @p receiver whenever a
    /// message may be waiting. @p ownPhysical is the interface's own
    /// physical address: the link passes on only messages to it or to the
    /// broadcast address.
    virtual Status Start(ObjectId receiver, uint32_t receiveEvent, uint32_t ownPhysical) = 0;
    /// Ends delivery; nothing is posted after it returns.
    virtual void Stop() = 0;
    /// Queues @p message for sending, from the link's own physical address
    /// (given to Start); Busy when the driver's queue is full or the link
    /// has not started.
    virtual Status Send(const SystemMessage& message) = 0;
    /// The next message that arrived for this node: true and @p message
    /// filled in, or false when none is waiting. Frames that are not system
    /// messages for this node are dropped and counted by the link.
    virtual Result<bool> Receive(SystemMessage& message) = 0;

protected:
    ~NetworkLink() = default;
};

} // namespace dcos
