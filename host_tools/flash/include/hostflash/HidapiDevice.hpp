// An MCP2221A reached through hidapi's hidraw back end (Debian's
// libhidapi-hidraw0): the HidDevice Mcp2221Lines drives. Linked only into
// dcos-flash (-lhidapi-hidraw), not into the unit tests, which use a fake.
//
// Linux's own hid-mcp2221 starts the device without a hidraw node (in
// current kernels, Debian's 6.1 among them: its module calls
// hid_hw_start() with no connect flags), so an MCP2221A that driver holds
// is not seen here; docs/guide/flashing.md says how to leave the device to
// hid-generic, which gives it one.
#pragma once

#include <hostflash/Mcp2221Lines.hpp>

#include <memory>
#include <string>

namespace hostflash {

/// Why no device was opened.
enum class HidOpenError : uint8_t {
    None,
    NotFound, ///< No MCP2221A (with that serial number), or hidapi could not start.
    Failed,   ///< One was found, and opening it failed (permissions, say).
};

class HidapiDevice final : public HidDevice {
public:
    /// Opens an MCP2221A (VID 0x04D8, PID 0x00DD): the first one when
    /// @p selector is empty, the one at @p selector when it is a path
    /// ("/dev/hidraw3"), else the one whose USB serial number is
    /// @p selector. Null, with @p error and @p why, when there is none.
    static std::unique_ptr<HidapiDevice> open(const std::string& selector, HidOpenError& error, std::string& why);

    ~HidapiDevice() override;
    HidapiDevice(const HidapiDevice&) = delete;
    HidapiDevice& operator=(const HidapiDevice&) = delete;

    bool write(const mcp2221::Report& report, std::string& why) override;
    int read(uint8_t* buffer, size_t capacity, std::chrono::milliseconds timeout, std::string& why) override;

    /// The device's path, for messages.
    const std::string& path() const { return path_; }

private:
    HidapiDevice(void* handle, std::string path) : handle_(handle), path_(std::move(path)) {}

    void* handle_; // hid_device*, kept out of this header so hidapi.h is the source's alone.
    std::string path_;
};

} // namespace hostflash
