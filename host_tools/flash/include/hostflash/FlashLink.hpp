// How dcos-flash reaches a node: a byte stream carrying the flash
// protocol's serial frames (docs/protocols/flash.md). A serial device
// (/dev/ttyUSB0, at 115200 bit/s 8N1, raw) or a Unix socket (the emulated
// board's console, unix:/path).
#pragma once

#include <flash/FlashMessage.hpp>
#include <flash/SerialFramer.hpp>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hostflash {

enum class LinkError : uint8_t {
    None,
    BadArgument,  ///< The device text names no transport.
    NotAvailable, ///< No such device or socket.
    Failed,       ///< I/O failed, or the other end went away.
    Timeout,      ///< No valid reply in time.
};

class FlashLink {
public:
    /// Opens "unix:/path" or a serial device path; null with @p error and @p why.
    static std::unique_ptr<FlashLink> open(const std::string& device, LinkError& error, std::string& why);

    ~FlashLink();
    FlashLink(const FlashLink&) = delete;
    FlashLink& operator=(const FlashLink&) = delete;

    /// Sends @p request framed, and waits up to @p timeout for a frame whose
    /// message decodes with the request's tag; bytes that are no such frame
    /// (console text, a stale reply) are skipped.
    LinkError exchange(const flash::FlashMessage& request, flash::FlashMessage& reply,
                       std::chrono::milliseconds timeout, std::string& why);

    /// Frames dropped as damaged so far.
    uint32_t damagedFrames() const { return receiver_.dropped(); }

private:
    explicit FlashLink(int descriptor) : descriptor_(descriptor) {}

    int descriptor_;
    flash::SerialFramer receiver_;
};

} // namespace hostflash
