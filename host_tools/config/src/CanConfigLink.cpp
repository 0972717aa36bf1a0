#include <hostconfig/CanConfigLink.hpp>

#include <can/IsoTpPci.hpp>

#include <fmt/core.h>

#include <algorithm>

namespace hostconfig {

namespace {

using Clock = std::chrono::steady_clock;

// More frames than a 1 Mbit/s bus carries in the time between two probes.
constexpr unsigned kMaxDropped = 1000;

LinkError linkErrorOf(const hostcan::TransportError& error)
{
    switch (error.kind) {
    case hostcan::TransportError::Kind::None: return LinkError::None;
    case hostcan::TransportError::Kind::NotAvailable: return LinkError::NotAvailable;
    case hostcan::TransportError::Kind::BadArgument: return LinkError::BadArgument;
    // Nobody acknowledged the frame (or the interface is off the bus): as
    // silence, which says "no answer", not "the interface broke".
    case hostcan::TransportError::Kind::Refused: return LinkError::Silent;
    default: return LinkError::Failed;
    }
}

// What every matching node sends for a ProbeSerial: the ISO-TP single
// frame of the two-byte reply [0xA0][Ok] (CanSeiServer::scan).
constexpr uint8_t kProbeAnswer[] = {
    can::IsoTpPci::pciByte(can::PciType::SingleFrame, 2),
    static_cast<uint8_t>(static_cast<uint8_t>(sei::SeiCommand::ProbeSerial) | sei::kSeiReplyBit),
    static_cast<uint8_t>(sei::SeiStatus::Ok),
};

} // namespace

can::CanFrame broadcastFrame(const can::IsoTpConfig& broadcast, const uint8_t* message, uint8_t length)
{
    uint8_t bytes[can::CanFrame::kMaxDataLength] = {};
    const uint8_t carried = length < can::IsoTpPci::kMaxSingleFrameData ? length : can::IsoTpPci::kMaxSingleFrameData;
    bytes[0] = can::IsoTpPci::pciByte(can::PciType::SingleFrame, carried);
    std::copy(message, message + carried, bytes + 1);
    return can::IsoTpPci::makeFrame(broadcast.txId, can::IdFormat::Extended, bytes, static_cast<uint8_t>(carried + 1),
                                    broadcast.padding);
}

bool isProbeAnswer(const can::CanFrame& frame, const can::IsoTpConfig& broadcast)
{
    // A node pads its answer as the connection says, so only the first
    // bytes are compared.
    if (!frame.isExtended() || frame.isRemote() || frame.id() != broadcast.rxId ||
        frame.length() < sizeof kProbeAnswer) {
        return false;
    }
    return std::equal(std::begin(kProbeAnswer), std::end(kProbeAnswer), frame.data());
}

CanConfigLink::CanConfigLink(const std::string& interface, const CanConfigAddress& address)
    : interface_(interface), address_(address),
      broadcast_(sei::canSeiConnection(can::MessageIdentifier::kBroadcast, address.host, address.priority, true))
{
}

namespace {

// Addresses no node could answer: said before anything is opened.
bool addressesRefused(const CanConfigAddress& address, LinkError& error, std::string& why)
{
    if (address.host > can::MessageIdentifier::kMaxNodeNumber || address.node == address.host ||
        address.priority > can::MessageIdentifier::kLowestPriority) {
        error = LinkError::BadArgument;
        why = fmt::format("CAN node numbers are 0 to {} (255: the broadcast address), the tool's ({}) must differ "
                          "from the node's ({}), and priorities are 0 to {}",
                          can::MessageIdentifier::kMaxNodeNumber, address.host, address.node,
                          can::MessageIdentifier::kLowestPriority);
        return true;
    }
    return false;
}

} // namespace

std::unique_ptr<CanConfigLink> CanConfigLink::open(const std::string& interface, const CanConfigAddress& address,
                                                   LinkError& error, std::string& why)
{
    if (addressesRefused(address, error, why)) {
        return nullptr;
    }
    std::unique_ptr<CanConfigLink> link(new CanConfigLink(interface, address));
    hostcan::TransportError opened;
    link->requester_ = hostcan::IsoTpRequester::open(
        interface, sei::canSeiConnection(address.node, address.host, address.priority, true), address.kernelIsoTp,
        opened);
    if (opened) {
        error = opened.kind == hostcan::TransportError::Kind::Refused ? LinkError::Failed : linkErrorOf(opened);
        why = opened.message;
        return nullptr;
    }
    return link;
}

std::unique_ptr<CanConfigLink> CanConfigLink::over(std::unique_ptr<hostcan::Transport> transport,
                                                   const CanConfigAddress& address, LinkError& error, std::string& why)
{
    if (addressesRefused(address, error, why)) {
        return nullptr;
    }
    const std::string name = transport->name();
    std::unique_ptr<CanConfigLink> link(new CanConfigLink(name, address));
    link->requester_ = hostcan::IsoTpRequester::over(
        std::move(transport), sei::canSeiConnection(address.node, address.host, address.priority, true));
    return link;
}

LinkError CanConfigLink::exchange(const Bytes& request, sei::SeiCommand command, Bytes& reply,
                                  std::chrono::milliseconds timeout, std::string& why)
{
    const hostcan::ExchangeOutcome outcome =
        requester_->exchange(request, timeout, [&](const std::vector<uint8_t>& received) {
            sei::SeiMessage decoded;
            return answers(command, received.data(), received.size(), decoded);
        });
    switch (outcome.result) {
    case hostcan::ExchangeResult::Replied: reply = outcome.reply; return LinkError::None;
    case hostcan::ExchangeResult::Silent:
        why = outcome.why;
        return LinkError::Silent;
    case hostcan::ExchangeResult::Failed: why = outcome.why; return linkErrorOf(outcome.transport);
    }
    return LinkError::Failed;
}

hostcan::Transport* CanConfigLink::frames(LinkError& error, std::string& why)
{
    if (hostcan::Transport* own = requester_->transport(); own != nullptr) {
        return own;
    }
    // The kernel's ISO-TP socket hands over whole messages only; the
    // probes and their answers are frames, so a raw socket on the same
    // interface carries them (the kernel gives every socket its copy).
    if (!raw_) {
        hostcan::TransportError opened;
        raw_ = hostcan::openTransport(interface_, opened);
        if (opened) {
            error = linkErrorOf(opened);
            why = opened.message;
            raw_.reset();
            return nullptr;
        }
    }
    return raw_.get();
}

LinkError CanConfigLink::sendBroadcast(const uint8_t* message, uint8_t length, std::string& why)
{
    LinkError error = LinkError::None;
    hostcan::Transport* transport = frames(error, why);
    if (transport == nullptr) {
        return error;
    }
    if (const hostcan::TransportError sent =
            transport->send(broadcastFrame(broadcast_, message, length), std::chrono::milliseconds(100))) {
        why = sent.message;
        return linkErrorOf(sent);
    }
    return LinkError::None;
}

LinkError CanConfigLink::probe(uint8_t bits, uint32_t value, bool& answered, std::string& why)
{
    answered = false;
    LinkError error = LinkError::None;
    hostcan::Transport* transport = frames(error, why);
    if (transport == nullptr) {
        return error;
    }
    // Every answer is the same frame, so one to an earlier probe that came
    // late would pass for an answer to this one: drop what is waiting (a
    // bounded number, so a bus that never falls quiet cannot hold the scan).
    for (unsigned dropped = 0; dropped < kMaxDropped; ++dropped) {
        hostcan::TransportError failed;
        const hostcan::Received stale = transport->receive(std::chrono::milliseconds(0), failed);
        if (failed) {
            why = failed.message;
            return linkErrorOf(failed);
        }
        if (stale.kind == hostcan::Received::Kind::Timeout) {
            break;
        }
    }
    sei::SeiMessage request;
    request.kind = sei::SeiMessageKind::Request;
    request.command = sei::SeiCommand::ProbeSerial;
    request.probeBits = bits;
    request.probeValue = value;
    uint8_t bytes[can::IsoTpPci::kMaxSingleFrameData] = {};
    const size_t length = request.encode(bytes, sizeof bytes);
    if (length == 0) {
        why = "the probe does not encode";
        return LinkError::BadArgument;
    }
    if (const LinkError sent = sendBroadcast(bytes, static_cast<uint8_t>(length), why); sent != LinkError::None) {
        return sent;
    }
    // The whole wait, even after a first answer: nodes that answer a little
    // later send the same frame again, and it must not be left for the next
    // probe to find.
    const auto deadline = Clock::now() + address_.probeWait;
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        if (left.count() <= 0) {
            return LinkError::None;
        }
        hostcan::TransportError failed;
        const hostcan::Received received = transport->receive(left, failed);
        if (failed) {
            why = failed.message;
            return linkErrorOf(failed);
        }
        if (received.kind == hostcan::Received::Kind::Frame && isProbeAnswer(received.frame, broadcast_)) {
            answered = true;
        }
    }
}

LinkError CanConfigLink::announce(const Bytes& request, std::string& why)
{
    return sendBroadcast(request.data(), request.size(), why);
}

} // namespace hostconfig
