#include <hostflash/Mcp2221Lines.hpp>

#include <fmt/core.h>

#include <thread>

namespace hostflash {

using namespace mcp2221;

namespace {

LineResult badReply(const ReplyCheck& check)
{
    return LineResult{LineError::BadReply, check.detail};
}

} // namespace

LineResult Mcp2221Lines::exchange(const Report& request, uint8_t (&reply)[kReportSize], size_t& length)
{
    std::string why;
    if (!device_.write(request, why)) {
        return LineResult{LineError::Io, fmt::format("the MCP2221A does not take {}: {}",
                                                      commandText(static_cast<Command>(request[0])), why)};
    }
    const int read = device_.read(reply, sizeof reply, kReplyTimeout, why);
    if (read < 0) {
        return LineResult{LineError::Io, fmt::format("reading the MCP2221A's answer to {} failed: {}",
                                                      commandText(static_cast<Command>(request[0])), why)};
    }
    if (read == 0) {
        return LineResult{LineError::Timeout, fmt::format("the MCP2221A did not answer {} within {} ms",
                                                           commandText(static_cast<Command>(request[0])),
                                                           kReplyTimeout.count())};
    }
    length = static_cast<size_t>(read);
    return {};
}

LineResult Mcp2221Lines::configure()
{
    if (wiring_.resetPin >= kPinCount || wiring_.strapPin >= kPinCount) {
        return LineResult{LineError::BadArgument, "the MCP2221A's pins are GP0 to GP3"};
    }
    if (wiring_.resetPin == wiring_.strapPin) {
        return LineResult{LineError::BadArgument, "the reset line and the strap need a pin each"};
    }
    uint8_t reply[kReportSize];
    size_t length = 0;
    LineResult result = exchange(request(Command::GetSramSettings), reply, length);
    if (!result.ok()) {
        return result;
    }
    std::array<uint8_t, kPinCount> settings{};
    if (const ReplyCheck check = readSramGpioSettings(reply, length, settings); !check.ok()) {
        return badReply(check);
    }
    const uint8_t outputs = static_cast<uint8_t>((1u << wiring_.resetPin) | (1u << wiring_.strapPin));
    result = exchange(setGpioDesignations(settings, outputs), reply, length);
    if (!result.ok()) {
        return result;
    }
    if (const ReplyCheck check = checkReply(Command::SetSramSettings, reply, length); !check.ok()) {
        return badReply(check);
    }
    result = exchange(request(Command::GetGpioValues), reply, length);
    if (!result.ok()) {
        return result;
    }
    GpioValues values;
    if (const ReplyCheck check = readGpioValues(reply, length, values); !check.ok()) {
        return badReply(check);
    }
    for (const unsigned pin : {wiring_.resetPin, wiring_.strapPin}) {
        const PinState& state = values.pins[pin];
        if (!state.gpio || !state.output || !state.high) {
            return LineResult{LineError::BadReply,
                              fmt::format("GP{} of the MCP2221A is not a released GPIO output after SET SRAM "
                                          "SETTINGS ({}, {}, {})",
                                          pin, state.gpio ? "GPIO" : "not a GPIO", state.output ? "output" : "input",
                                          state.high ? "high" : "low")};
        }
    }
    return {};
}

LineResult Mcp2221Lines::drive(unsigned pin, bool high)
{
    uint8_t reply[kReportSize];
    size_t length = 0;
    const LineResult result = exchange(setPin(pin, high, true), reply, length);
    if (!result.ok()) {
        return result;
    }
    if (const ReplyCheck check = readSetPinReply(reply, length, pin); !check.ok()) {
        return badReply(check);
    }
    return {};
}

LineResult Mcp2221Lines::setStrap(bool asserted)
{
    return drive(wiring_.strapPin, !asserted);
}

LineResult Mcp2221Lines::setReset(bool asserted)
{
    return drive(wiring_.resetPin, !asserted);
}

LineResult Mcp2221Lines::pulseReset(std::chrono::milliseconds width)
{
    LineResult result = setReset(true);
    if (!result.ok()) {
        return result;
    }
    std::this_thread::sleep_for(width);
    return setReset(false);
}

} // namespace hostflash
