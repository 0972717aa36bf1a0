// The message types of the DCOS identifier (docs/protocols/can.md, "Message types").
//
// The type field sits just below the priority in the identifier, so at equal
// task priority the lower type wins arbitration. The values are reserved here
// for the layers that come next; this layer gives them no behaviour beyond
// carrying them, and refuses the values not listed (a node cannot act on a
// type it does not know). The values travel on the bus and are never
// renumbered; families are spaced 0x10 apart so that a related type added
// later sits next to its family and keeps this tie-break order.
#pragma once

#include <stdint.h>

namespace can {

enum class MessageType : uint8_t {
    /// Clock synchronisation towards the global time base (seed 5.5). Lowest
    /// value: its content depends on the moment it is sent, so it should lose
    /// as little time in arbitration as possible.
    TimeSync = 0x01,
    /// The reply of a remote transaction (seed 6.4, Fig. 6.3). Ahead of the
    /// request: it completes work a task is already blocked on.
    RemoteReply = 0x10,
    /// A remote service request sent by a system agent for a task (seed 6.4).
    RemoteRequest = 0x11,
    /// A name lookup asked of every node: which one has an object of this
    /// type and name visible to the asker (seed 6.4, NameToObject). Answered
    /// with a RemoteReply by the node that has one.
    NameQuery = 0x12,
    /// A remote request for a node behind a gateway, sent to the gateway: a
    /// route header naming the logical destination, then the request's
    /// frames (docs/protocols/remote-transactions.md, "Gateways").
    RoutedRequest = 0x13,
    /// A node's first message on a bus since it started, to every node:
    /// what they keep for its tasks of before (a semaphore a task of it
    /// held, a timer one owned) belongs to tasks that no longer run
    /// (docs/protocols/remote-transactions.md, "A node that starts again").
    NodeStarted = 0x14,
    /// A distributed shared memory publication (seed 7.10).
    DsmPublication = 0x20,
    /// A publication of a node behind a gateway, relayed by the gateway: a
    /// relay header naming the publisher's node before each frame
    /// (docs/protocols/publications.md, "Across a gateway").
    RelayedPublication = 0x21,
    /// A segmented transfer, ISO 15765-2 (IsoTpSender, IsoTpReceiver).
    Segmented = 0x30,
    /// Configuration by the system engineering interface agent (seed 7.14).
    Configuration = 0x40,
    /// The stream a node sends the host that asked for it with the
    /// configuration protocol's Monitor command: samples of publications
    /// and console output, unacknowledged (seed 7.14, 8.3;
    /// docs/protocols/monitor.md). Next to Configuration, whose command
    /// starts it, and ahead of Flashing: a few frames a period that a
    /// control engineer watches live.
    Monitoring = 0x41,
    /// Program download into a node: the SEI agent's file transfer (seed 7.14).
    Flashing = 0x50,
};

/// Whether @p raw is one of the assigned message types.
constexpr bool isAssignedMessageType(uint8_t raw)
{
    switch (static_cast<MessageType>(raw)) {
    case MessageType::TimeSync:
    case MessageType::RemoteReply:
    case MessageType::RemoteRequest:
    case MessageType::NameQuery:
    case MessageType::RoutedRequest:
    case MessageType::NodeStarted:
    case MessageType::DsmPublication:
    case MessageType::RelayedPublication:
    case MessageType::Segmented:
    case MessageType::Configuration:
    case MessageType::Monitoring:
    case MessageType::Flashing:
        return true;
    }
    return false;
}

/// A short, stable English name for @p type, for logs and the console.
constexpr const char* messageTypeName(MessageType type)
{
    switch (type) {
    case MessageType::TimeSync: return "time sync";
    case MessageType::RemoteReply: return "remote reply";
    case MessageType::RemoteRequest: return "remote request";
    case MessageType::NameQuery: return "name query";
    case MessageType::RoutedRequest: return "routed request";
    case MessageType::NodeStarted: return "node started";
    case MessageType::DsmPublication: return "DSM publication";
    case MessageType::RelayedPublication: return "relayed publication";
    case MessageType::Segmented: return "segmented";
    case MessageType::Configuration: return "configuration";
    case MessageType::Monitoring: return "monitoring";
    case MessageType::Flashing: return "flashing";
    }
    return "unassigned";
}

} // namespace can
