#include <hostflash/CanFlashLink.hpp>

#include <hostcan/IsoTpEndpoint.hpp>

#include <can/MessageIdentifier.hpp>

#include <fmt/core.h>

namespace hostflash {

namespace {

LinkError linkErrorOf(const hostcan::TransportError& error)
{
    switch (error.kind) {
    case hostcan::TransportError::Kind::None: return LinkError::None;
    case hostcan::TransportError::Kind::NotAvailable: return LinkError::NotAvailable;
    case hostcan::TransportError::Kind::BadArgument: return LinkError::BadArgument;
    default: return LinkError::Failed;
    }
}

} // namespace

std::unique_ptr<CanFlashLink> CanFlashLink::open(const std::string& interface, const CanFlashAddress& address,
                                                 LinkError& error, std::string& why)
{
    if (address.node > can::MessageIdentifier::kMaxNodeNumber || address.host > can::MessageIdentifier::kMaxNodeNumber ||
        address.node == address.host) {
        error = LinkError::BadArgument;
        why = fmt::format("CAN node numbers are 0 to {}, and the tool's ({}) must differ from the node's ({})",
                          can::MessageIdentifier::kMaxNodeNumber, address.host, address.node);
        return nullptr;
    }
    std::unique_ptr<CanFlashLink> link(
        new CanFlashLink(address, flash::canFlashConnection(address.node, address.host, address.priority, true)));
    hostcan::TransportError opened;
    if (address.kernelIsoTp) {
        link->kernel_ = hostcan::KernelIsoTpSocket::open(interface, link->config_, opened);
    } else {
        link->transport_ = hostcan::openTransport(interface, opened);
    }
    if (opened) {
        error = linkErrorOf(opened);
        why = opened.message;
        return nullptr;
    }
    return link;
}

LinkError CanFlashLink::exchange(const flash::FlashMessage& request, flash::FlashMessage& reply,
                                 std::chrono::milliseconds timeout, std::string& why)
{
    std::vector<uint8_t> bytes(flash::kMaxMessage);
    bytes.resize(request.encode(bytes.data(), bytes.size()));
    if (bytes.empty()) {
        why = "the request does not encode";
        return LinkError::BadArgument;
    }
    const hostcan::IsoTpOutcome sent =
        kernel_ ? kernel_->send(bytes, timeout) : hostcan::isoTpSend(*transport_, config_, bytes);
    if (sent.transport) {
        why = sent.transport.message;
        // Nobody acknowledged the frame: the node may be restarting, so
        // this is silence, worth asking again, not a broken link.
        return sent.transport.kind == hostcan::TransportError::Kind::Refused ? LinkError::Timeout
                                                                            : linkErrorOf(sent.transport);
    }
    if (sent.error != can::LinkError::Ok) {
        // The node took no part of it (no flow control): as silence.
        why = fmt::format("node {} did not take the request: {}", address_.node, can::linkErrorName(sent.error));
        return LinkError::Timeout;
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) {
            why = "no reply";
            return LinkError::Timeout;
        }
        const hostcan::IsoTpOutcome received =
            kernel_ ? kernel_->receive(left) : hostcan::isoTpReceive(*transport_, config_, left);
        if (received.transport) {
            why = received.transport.message;
            return linkErrorOf(received.transport);
        }
        if (received.error != can::LinkError::Ok) {
            continue; // A reply that broke off, or none yet: wait out the time.
        }
        flash::FlashMessage decoded;
        if (flash::FlashMessage::decode(received.message.data(), received.message.size(), decoded) &&
            decoded.tag == request.tag) {
            reply = decoded;
            return LinkError::None;
        }
    }
}

} // namespace hostflash
