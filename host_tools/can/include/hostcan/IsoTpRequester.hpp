// A host's end of a request-and-reply protocol over one ISO 15765-2
// connection (the flash protocol, the configuration protocol): each request
// and each reply one transfer. Through any hostcan transport with the link
// layer's own ISO-TP (IsoTpEndpoint.hpp), or through the Linux kernel's
// can-isotp socket on a SocketCAN interface (KernelIsoTp.hpp).
#pragma once

#include <hostcan/KernelIsoTp.hpp>
#include <hostcan/Transport.hpp>

#include <can/IsoTpConfig.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hostcan {

/// How an exchange ended.
enum class ExchangeResult {
    Replied,  ///< A reply the caller accepted is in `reply`.
    Silent,   ///< Nobody acknowledged the request, took it, or answered in time: worth asking again.
    Failed,   ///< The transport failed (`transport` says how).
};

struct ExchangeOutcome {
    ExchangeResult result = ExchangeResult::Silent;
    TransportError transport;
    std::vector<uint8_t> reply;
    std::string why; ///< For Silent and Failed: what happened, in words.
};

class IsoTpRequester {
public:
    /// Opens @p interface as `dcos-can -i` takes it for the connection
    /// @p config (the host's side); null, with @p error, when it cannot.
    static std::unique_ptr<IsoTpRequester> open(const std::string& interface, const can::IsoTpConfig& config,
                                                bool kernelIsoTp, TransportError& error);
    /// Over a transport already open: a tool that also reads other frames
    /// on the same interface (dcos-mon's stream) passes every frame through
    /// a transport of its own that sees them first.
    static std::unique_ptr<IsoTpRequester> over(std::unique_ptr<Transport> transport, const can::IsoTpConfig& config);

    /// Sends @p request and waits up to @p timeout for a reply @p accept
    /// takes (a reply to another request, left from an earlier exchange,
    /// is passed over).
    ExchangeOutcome exchange(const std::vector<uint8_t>& request, std::chrono::milliseconds timeout,
                             const std::function<bool(const std::vector<uint8_t>&)>& accept);

    /// The frame transport, for traffic outside the connection (a scan's
    /// probes to the broadcast address); null on a kernel ISO-TP socket.
    Transport* transport() { return transport_.get(); }

private:
    explicit IsoTpRequester(const can::IsoTpConfig& config) : config_(config) {}

    can::IsoTpConfig config_;
    std::unique_ptr<Transport> transport_;
    std::unique_ptr<KernelIsoTpSocket> kernel_;
};

} // namespace hostcan
