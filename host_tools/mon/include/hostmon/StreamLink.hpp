// dcos-mon's one connection to the bus: the configuration protocol's
// requests to one node (hostconfig::ConfigLink, so hostconfig::ConfigClient
// asks, authenticates and checks the replies as it does for dcos-config)
// and the node's monitoring stream, through ONE transport. A lab bus port or
// an slcan adapter can be opened once per process, and a frame of the
// stream that arrives while a renewal's transfer runs must not be lost: the
// transfer's frames pass through a tap that sets the stream's frames aside
// for the tool to read after.
#pragma once

#include <hostconfig/CanConfigLink.hpp>
#include <hostconfig/ConfigLink.hpp>

#include <hostcan/Transport.hpp>

#include <can/IsoTpConfig.hpp>
#include <can/MessageIdentifier.hpp>
#include <sei/CanSeiServer.hpp>

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>

namespace hostmon {

/// A frame of the stream as it arrived.
struct StreamArrival {
    can::CanFrame frame;
    /// The transport's timestamp (the lab bus's emulated time, exact), or
    /// the host's monotonic clock when the transport has none.
    std::chrono::nanoseconds timestamp{0};
    bool emulatedTime = false;
};

struct StreamAddress {
    /// The node's CAN node number, or the broadcast address 255: the
    /// selected node (its requests and replies; its stream comes from its
    /// own number, set with setStreamSource once Identify has said it).
    uint8_t node = can::MessageIdentifier::kBroadcast;
    uint8_t host = sei::kCanSeiHostNode;
    uint8_t priority = sei::kCanSeiPriority;
};

class StreamLink final : public hostconfig::ConfigLink {
public:
    /// Opens @p interface as `dcos-can -i` takes it; null with @p error and
    /// @p why when it cannot (or the addresses are wrong: BadArgument).
    static std::unique_ptr<StreamLink> open(const std::string& interface, const StreamAddress& address,
                                            hostconfig::LinkError& error, std::string& why);
    /// Over a transport already open.
    static std::unique_ptr<StreamLink> over(std::unique_ptr<hostcan::Transport> transport,
                                            const StreamAddress& address, hostconfig::LinkError& error,
                                            std::string& why);

    /// The configuration protocol's requests, as hostconfig::CanConfigLink
    /// carries them; the stream's frames that pass meanwhile are set aside.
    hostconfig::LinkError exchange(const hostconfig::Bytes& request, sei::SeiCommand command,
                                   hostconfig::Bytes& reply, std::chrono::milliseconds timeout,
                                   std::string& why) override;
    /// dcos-mon never scans; BadArgument.
    hostconfig::LinkError probe(uint8_t bits, uint32_t value, bool& answered, std::string& why) override;
    hostconfig::LinkError announce(const hostconfig::Bytes& request, std::string& why) override;

    /// The CAN node number the stream's frames come from.
    void setStreamSource(uint8_t node) { streamSource_ = node; }

    /// Waits at most @p timeout for the next frame of the stream (those set
    /// aside during a transfer first); false on time-out. @p error when the
    /// transport failed.
    bool receive(std::chrono::milliseconds timeout, StreamArrival& out, hostcan::TransportError& error);

    /// Stream frames set aside and dropped because the tool did not read
    /// them (more than a bounded backlog).
    unsigned overflowed() const { return overflowed_; }

private:
    class Tap;

    explicit StreamLink(const StreamAddress& address) : address_(address), streamSource_(address.node) {}

    void setAside(const hostcan::Received& received);

    StreamAddress address_;
    uint8_t streamSource_;
    // The requests' link, over the tap, which owns the interface's transport.
    std::unique_ptr<hostconfig::CanConfigLink> link_;
    std::deque<StreamArrival> aside_;
    unsigned overflowed_ = 0;
};

} // namespace hostmon
