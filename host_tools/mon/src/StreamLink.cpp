#include <hostmon/StreamLink.hpp>

#include <hostmon/StreamDecoder.hpp>

#include <hostconfig/CanConfigLink.hpp>
#include <hostconfig/ConfigRequest.hpp>

#include <can/IsoTpPci.hpp>

#include <fmt/core.h>

namespace hostmon {

namespace {

using hostconfig::LinkError;
using Clock = std::chrono::steady_clock;

// More than a minute of the largest stream (eight channels every 10 ms):
// a tool held up longer than that has lost the live view anyway.
constexpr size_t kMaxAside = 65536;

std::chrono::nanoseconds monotonicNow()
{
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch());
}

} // namespace

// The interface's transport as the requests' link sees it: every frame
// passes, and a frame of the stream is also kept for the tool (a transfer
// passes over it, its identifier being another).
class StreamLink::Tap final : public hostcan::Transport {
public:
    Tap(StreamLink& link, std::unique_ptr<hostcan::Transport> transport)
        : link_(link), transport_(std::move(transport))
    {
    }

    std::string name() const override { return transport_->name(); }
    hostcan::TransportError send(const can::CanFrame& frame, std::chrono::milliseconds timeout) override
    {
        return transport_->send(frame, timeout);
    }
    hostcan::Received receive(std::chrono::milliseconds timeout, hostcan::TransportError& error) override
    {
        hostcan::Received received = transport_->receive(timeout, error);
        link_.setAside(received);
        return received;
    }
    std::optional<uint32_t> bitRate() const override { return transport_->bitRate(); }

private:
    StreamLink& link_;
    std::unique_ptr<hostcan::Transport> transport_;
};

std::unique_ptr<StreamLink> StreamLink::open(const std::string& interface, const StreamAddress& address,
                                             LinkError& error, std::string& why)
{
    hostcan::TransportError opened;
    std::unique_ptr<hostcan::Transport> transport = hostcan::openTransport(interface, opened);
    if (opened || !transport) {
        error = opened.kind == hostcan::TransportError::Kind::BadArgument ? LinkError::BadArgument
                                                                           : LinkError::NotAvailable;
        why = opened.message;
        return nullptr;
    }
    return over(std::move(transport), address, error, why);
}

std::unique_ptr<StreamLink> StreamLink::over(std::unique_ptr<hostcan::Transport> transport,
                                             const StreamAddress& address, LinkError& error, std::string& why)
{
    std::unique_ptr<StreamLink> link(new StreamLink(address));
    hostconfig::CanConfigAddress configAddress;
    configAddress.node = address.node;
    configAddress.host = address.host;
    configAddress.priority = address.priority;
    link->link_ = hostconfig::CanConfigLink::over(std::make_unique<Tap>(*link, std::move(transport)), configAddress,
                                                  error, why);
    return link->link_ ? std::move(link) : nullptr;
}

void StreamLink::setAside(const hostcan::Received& received)
{
    if (received.kind != hostcan::Received::Kind::Frame ||
        !isStreamFrame(received.frame, address_.host, streamSource_)) {
        return;
    }
    if (aside_.size() >= kMaxAside) {
        ++overflowed_;
        return;
    }
    StreamArrival arrival;
    arrival.frame = received.frame;
    arrival.emulatedTime = received.emulatedTime;
    arrival.timestamp = received.timestamp.count() != 0 ? received.timestamp : monotonicNow();
    aside_.push_back(arrival);
}

LinkError StreamLink::exchange(const hostconfig::Bytes& request, sei::SeiCommand command, hostconfig::Bytes& reply,
                               std::chrono::milliseconds timeout, std::string& why)
{
    return link_->exchange(request, command, reply, timeout, why);
}

LinkError StreamLink::probe(uint8_t, uint32_t, bool& answered, std::string& why)
{
    answered = false;
    why = "dcos-mon does not scan: `dcos-config scan` lists the nodes";
    return LinkError::BadArgument;
}

LinkError StreamLink::announce(const hostconfig::Bytes& request, std::string& why)
{
    return link_->announce(request, why);
}

bool StreamLink::receive(std::chrono::milliseconds timeout, StreamArrival& out, hostcan::TransportError& error)
{
    hostcan::Transport& tap = *link_->transport();
    const auto deadline = Clock::now() + timeout;
    for (;;) {
        if (!aside_.empty()) {
            out = aside_.front();
            aside_.pop_front();
            return true;
        }
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        // Through the tap, which sets a stream frame aside.
        const hostcan::Received received = tap.receive(left.count() > 0 ? left : std::chrono::milliseconds(0), error);
        if (error) {
            return false;
        }
        if (received.kind == hostcan::Received::Kind::Timeout && left.count() <= 0) {
            return false;
        }
        if (aside_.empty() && Clock::now() >= deadline) {
            return false;
        }
    }
}

} // namespace hostmon
