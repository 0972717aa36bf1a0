#include <hostflash/CanFlashLink.hpp>


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
    std::unique_ptr<CanFlashLink> link(new CanFlashLink(address));
    hostcan::TransportError opened;
    link->requester_ = hostcan::IsoTpRequester::open(
        interface, flash::canFlashConnection(address.node, address.host, address.priority, true), address.kernelIsoTp,
        opened);
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
    const hostcan::ExchangeOutcome outcome =
        requester_->exchange(bytes, timeout, [&](const std::vector<uint8_t>& received) {
            flash::FlashMessage decoded;
            if (!flash::FlashMessage::decode(received.data(), received.size(), decoded) ||
                decoded.tag != request.tag) {
                return false;
            }
            reply = decoded;
            return true;
        });
    switch (outcome.result) {
    case hostcan::ExchangeResult::Replied: return LinkError::None;
    case hostcan::ExchangeResult::Silent:
        why = fmt::format("node {}: {}", address_.node, outcome.why);
        return LinkError::Timeout;
    case hostcan::ExchangeResult::Failed: why = outcome.why; return linkErrorOf(outcome.transport);
    }
    return LinkError::Failed;
}

} // namespace hostflash
