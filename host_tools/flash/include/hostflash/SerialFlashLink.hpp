// The flash protocol on a byte stream, in its serial frames
// (docs/protocols/flash.md, "On a serial line"): a serial device
// (/dev/ttyUSB0, at 115200 bit/s 8N1, raw) or a Unix socket (the emulated
// board's console, unix:/path). The stage loader serves it in recovery.
#pragma once

#include <hostflash/FlashLink.hpp>

#include <flash/SerialFramer.hpp>

#include <memory>
#include <string>

namespace hostflash {

class SerialFlashLink final : public FlashLink {
public:
    /// Opens "unix:/path" or a serial device path; null with @p error and @p why.
    static std::unique_ptr<SerialFlashLink> open(const std::string& device, LinkError& error, std::string& why);

    ~SerialFlashLink() override;
    SerialFlashLink(const SerialFlashLink&) = delete;
    SerialFlashLink& operator=(const SerialFlashLink&) = delete;

    LinkError exchange(const flash::FlashMessage& request, flash::FlashMessage& reply,
                       std::chrono::milliseconds timeout, std::string& why) override;
    bool reachesRunningNode() const override { return false; }

    /// Frames dropped as damaged so far.
    uint32_t damagedFrames() const { return receiver_.dropped(); }

private:
    explicit SerialFlashLink(int descriptor) : descriptor_(descriptor) {}

    int descriptor_;
    flash::SerialFramer receiver_;
};

} // namespace hostflash
