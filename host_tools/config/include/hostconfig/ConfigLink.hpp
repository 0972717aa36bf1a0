// How dcos-config reaches the nodes: one request of the configuration
// protocol (docs/protocols/config.md) out, its reply back, on one
// connection (a node's own CAN node number, or the broadcast address where
// the selected node answers); and the scan's messages to every node on the
// bus, which go outside any connection. CanConfigLink carries them on CAN;
// the unit tests carry them to nodes in memory.
#pragma once

#include <hostconfig/ConfigRequest.hpp>

#include <sei/SeiMessage.hpp>

#include <chrono>
#include <cstdint>
#include <string>

namespace hostconfig {

enum class LinkError : uint8_t {
    None,
    BadArgument,  ///< The interface text names no transport, or the addresses are wrong.
    NotAvailable, ///< No such interface, socket or device (or no CAN in this kernel).
    Failed,       ///< I/O failed, or the other end went away.
    Silent,       ///< No answer in time, or nobody acknowledged the frame: worth asking again.
};

class ConfigLink {
public:
    virtual ~ConfigLink() = default;

    /// Sends @p request (the bytes of a request of @p command) on the
    /// link's connection and waits up to @p timeout for the bytes that
    /// answer it (hostconfig::answers); anything else that arrives is
    /// passed over.
    virtual LinkError exchange(const Bytes& request, sei::SeiCommand command, Bytes& reply,
                               std::chrono::milliseconds timeout, std::string& why) = 0;

    /// Sends ProbeSerial(@p bits, @p value) to every node on the bus and
    /// waits the probe's time for answers: @p answered when at least one
    /// came.
    virtual LinkError probe(uint8_t bits, uint32_t value, bool& answered, std::string& why) = 0;

    /// Sends @p request to every node on the bus, for the commands no node
    /// answers there (Deselect, ActivateBitRate): returns once it has gone.
    virtual LinkError announce(const Bytes& request, std::string& why) = 0;
};

} // namespace hostconfig
