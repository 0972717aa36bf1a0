// How dcos-flash reaches a node: one request of the flash protocol
// (docs/protocols/flash.md) out, its reply back, whatever carries them. A
// serial line carries them in the protocol's serial frames
// (SerialFlashLink), CAN in ISO-TP transfers (CanFlashLink).
#pragma once

#include <flash/FlashMessage.hpp>

#include <chrono>
#include <cstdint>
#include <string>

namespace hostflash {

enum class LinkError : uint8_t {
    None,
    BadArgument,  ///< The device or interface text names no transport.
    NotAvailable, ///< No such device, socket or interface (or no CAN in this kernel).
    Failed,       ///< I/O failed, or the other end went away.
    Timeout,      ///< No valid reply in time.
};

class FlashLink {
public:
    virtual ~FlashLink() = default;

    /// Sends @p request and waits up to @p timeout for a reply that decodes
    /// with the request's tag; anything else that arrives (console text, a
    /// stale reply to an earlier attempt) is skipped.
    virtual LinkError exchange(const flash::FlashMessage& request, flash::FlashMessage& reply,
                               std::chrono::milliseconds timeout, std::string& why) = 0;

    /// Whether the node can be asked again after it restarted (CAN: the
    /// running application's flash service answers; a serial line carries
    /// the protocol only in recovery).
    virtual bool reachesRunningNode() const = 0;
};

} // namespace hostflash
