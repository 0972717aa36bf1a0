// What the message port agent (seed 7.9) reports about itself, for the
// console's 'ports' command and the on-target tests.
#pragma once

#include <dcos/MessagePortAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// A copy of one port's state, taken under the agent's lock.
struct PortInfo {
    ObjectId id;
    ObjectId owner;             ///< The receiving task; null for the system.
    char name[16];              ///< Empty for an unnamed port.
    PortOrder order;
    size_t queued;              ///< Messages waiting to be received.
    uint32_t levelBits;         ///< Bit n set while level n holds messages.
    bool receiverWaiting;       ///< The owner is blocked in Receive.
};

/// The state of the message-buffer area.
struct MessageBufferCounts {
    size_t free;     ///< Buffers free for Send.
    size_t active;   ///< Buffers activated so far (at boot and by AddMsgBufs).
    size_t reserved; ///< Buffers reserved at build time.
};

class PortManager {
public:
    /// Port slots activated so far; snapshot() takes slots below this.
    static size_t activeCount();
    /// Ports that exist.
    static size_t portCount();
    /// Copies the state of the port in @p slot; false when the slot is free.
    static bool snapshot(size_t slot, PortInfo& info);
    /// The message-buffer area's counts.
    static MessageBufferCounts bufferCounts();
    /// A port named @p name visible from @p askingScope.
    static Result<ObjectId> nameToObject(const char* name, Visibility askingScope);
};

} // namespace dcos::internal
