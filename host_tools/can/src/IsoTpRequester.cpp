#include <hostcan/IsoTpRequester.hpp>

#include <hostcan/IsoTpEndpoint.hpp>

#include <fmt/core.h>

namespace hostcan {

std::unique_ptr<IsoTpRequester> IsoTpRequester::open(const std::string& interface, const can::IsoTpConfig& config,
                                                     bool kernelIsoTp, TransportError& error)
{
    std::unique_ptr<IsoTpRequester> requester(new IsoTpRequester(config));
    if (kernelIsoTp) {
        requester->kernel_ = KernelIsoTpSocket::open(interface, config, error);
    } else {
        requester->transport_ = openTransport(interface, error);
    }
    if (error) {
        return nullptr;
    }
    return requester;
}

std::unique_ptr<IsoTpRequester> IsoTpRequester::over(std::unique_ptr<Transport> transport,
                                                     const can::IsoTpConfig& config)
{
    std::unique_ptr<IsoTpRequester> requester(new IsoTpRequester(config));
    requester->transport_ = std::move(transport);
    return requester;
}

ExchangeOutcome IsoTpRequester::exchange(const std::vector<uint8_t>& request, std::chrono::milliseconds timeout,
                                         const std::function<bool(const std::vector<uint8_t>&)>& accept)
{
    ExchangeOutcome outcome;
    const IsoTpOutcome sent = kernel_ ? kernel_->send(request, timeout) : isoTpSend(*transport_, config_, request);
    if (sent.transport) {
        outcome.why = sent.transport.message;
        // Nobody acknowledged the frame: the node may be restarting, so
        // this is silence, worth asking again, not a broken link.
        if (sent.transport.kind == TransportError::Kind::Refused) {
            outcome.result = ExchangeResult::Silent;
        } else {
            outcome.result = ExchangeResult::Failed;
            outcome.transport = sent.transport;
        }
        return outcome;
    }
    if (sent.error != can::LinkError::Ok) {
        // The peer took no part of it (no flow control): as silence.
        outcome.why = fmt::format("the request was not taken: {}", can::linkErrorName(sent.error));
        return outcome;
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) {
            outcome.why = "no reply";
            return outcome;
        }
        const IsoTpOutcome received = kernel_ ? kernel_->receive(left) : isoTpReceive(*transport_, config_, left);
        if (received.transport) {
            outcome.result = ExchangeResult::Failed;
            outcome.transport = received.transport;
            outcome.why = received.transport.message;
            return outcome;
        }
        if (received.error != can::LinkError::Ok) {
            continue; // A reply that broke off, or none yet: wait out the time.
        }
        if (accept(received.message)) {
            outcome.result = ExchangeResult::Replied;
            outcome.reply = received.message;
            return outcome;
        }
    }
}

} // namespace hostcan
