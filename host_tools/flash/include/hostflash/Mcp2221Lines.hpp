// A controller's reset line and recovery strap on two GPIO pins of a
// Microchip MCP2221A (docs/guide/flashing.md, "Recovery through the reset
// and strap lines"): the pins are made GPIO outputs, released (high), and
// then pulled low and released again as dcos-flash --recover needs. Every
// command waits for its reply and checks it (Mcp2221.hpp); a reply that is
// short, answers another command, or reports a failure ends the work with
// a message that says so, and no line is touched after it.
//
// The HID device is an interface, so the sequence is tested with a fake
// device (host_tools/flash/unit_tests/Mcp2221LinesTest.cpp); HidapiDevice
// (HidapiDevice.hpp) is the real one, through hidapi's hidraw back end.
#pragma once

#include <hostflash/Mcp2221.hpp>

#include <chrono>
#include <cstdint>
#include <string>

namespace hostflash {

/// One HID device: a report out, a report in.
class HidDevice {
public:
    virtual ~HidDevice() = default;

    /// Sends @p report as one output report (no report ID). False, with
    /// @p why, when the device does not take it.
    virtual bool write(const mcp2221::Report& report, std::string& why) = 0;

    /// Waits up to @p timeout for one input report and copies it into
    /// @p buffer: the count of bytes read (0 on time-out, which is no
    /// error), or -1 with @p why when reading failed.
    virtual int read(uint8_t* buffer, size_t capacity, std::chrono::milliseconds timeout, std::string& why) = 0;
};

/// Why a line could not be driven.
enum class LineError : uint8_t {
    None,
    BadArgument, ///< A pin that is not GP0 to GP3, or reset and strap on one pin.
    Io,          ///< The device would not take a report or could not be read.
    Timeout,     ///< No reply in time.
    BadReply,    ///< A reply that is short, to another command, a failure, or nonsense.
};

/// The outcome of a step: the error and its message.
struct LineResult {
    LineError error = LineError::None;
    std::string message;

    bool ok() const { return error == LineError::None; }
};

/// Which pin is which line. Both lines are active low.
struct LineWiring {
    unsigned resetPin = 0; ///< GP0: pulls the board's reset line low.
    unsigned strapPin = 1; ///< GP1: pulls the recovery strap low.
};

class Mcp2221Lines {
public:
    /// How long one reply may take: a real MCP2221A answers in a
    /// millisecond or two; the slack is for a busy host.
    static constexpr std::chrono::milliseconds kReplyTimeout{2000};

    Mcp2221Lines(HidDevice& device, LineWiring wiring) : device_(device), wiring_(wiring) {}

    /// Makes both pins GPIO outputs, released (high), through SET SRAM
    /// SETTINGS, keeping the other two pins' settings as GET SRAM SETTINGS
    /// reads them; then checks with GET GPIO VALUES that both are outputs
    /// and high.
    LineResult configure();

    /// Pulls the recovery strap low (@p asserted) or releases it.
    LineResult setStrap(bool asserted);

    /// Pulls the reset line low (@p asserted) or releases it.
    LineResult setReset(bool asserted);

    /// Pulls the reset line low for @p width, then releases it.
    LineResult pulseReset(std::chrono::milliseconds width);

private:
    LineResult exchange(const mcp2221::Report& request, uint8_t (&reply)[mcp2221::kReportSize], size_t& length);
    LineResult drive(unsigned pin, bool high);

    HidDevice& device_;
    LineWiring wiring_;
};

} // namespace hostflash
