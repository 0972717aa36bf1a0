#include <hostflash/Mcp2221.hpp>

#include <fmt/core.h>

namespace hostflash::mcp2221 {

namespace {

ReplyCheck refused(ReplyError error, std::string detail)
{
    return ReplyCheck{error, std::move(detail)};
}

} // namespace

std::string commandText(Command command)
{
    const char* name = "?";
    switch (command) {
    case Command::StatusSetParameters: name = "STATUS/SET PARAMETERS"; break;
    case Command::SetGpioOutputValues: name = "SET GPIO OUTPUT VALUES"; break;
    case Command::GetGpioValues: name = "GET GPIO VALUES"; break;
    case Command::SetSramSettings: name = "SET SRAM SETTINGS"; break;
    case Command::GetSramSettings: name = "GET SRAM SETTINGS"; break;
    }
    return fmt::format("{} (0x{:02X})", name, static_cast<unsigned>(command));
}

Report request(Command command)
{
    Report report{};
    report[0] = static_cast<uint8_t>(command);
    return report;
}

Report setPin(unsigned pin, bool high, bool makeOutput)
{
    Report report = request(Command::SetGpioOutputValues);
    const size_t at = kSetGpioFirst + kSetGpioStride * pin;
    report[at] = 1;
    report[at + 1] = high ? 1 : 0;
    if (makeOutput) {
        report[at + 2] = 1;
        report[at + 3] = kDirectionOutput;
    }
    return report;
}

Report setGpioDesignations(const std::array<uint8_t, kPinCount>& settings, uint8_t outputPins)
{
    Report report = request(Command::SetSramSettings);
    report[kSetSramAlterGpio] = kAlterGpioConfiguration;
    for (unsigned pin = 0; pin < kPinCount; ++pin) {
        uint8_t setting = settings[pin];
        if ((outputPins >> pin) & 1) {
            // GPIO, output, released: the lines are pulled low only on purpose.
            setting = kDesignationGpio | kGpSettingOutputHigh;
        }
        report[kSetSramGpioFirst + pin] = setting;
    }
    return report;
}

ReplyCheck checkReply(Command command, const uint8_t* data, size_t length)
{
    if (length < kReportSize) {
        return refused(ReplyError::Short, fmt::format("the MCP2221A answered {} with {} bytes, not {}",
                                                      commandText(command), length, kReportSize));
    }
    if (data[0] != static_cast<uint8_t>(command)) {
        return refused(ReplyError::WrongCommand, fmt::format("the MCP2221A answered {} with a reply to command 0x{:02X}",
                                                             commandText(command), data[0]));
    }
    if (data[1] != kStatusCompleted) {
        return refused(ReplyError::Failed, fmt::format("the MCP2221A did not complete {}: status 0x{:02X}",
                                                       commandText(command), data[1]));
    }
    return {};
}

ReplyCheck readSramGpioSettings(const uint8_t* data, size_t length, std::array<uint8_t, kPinCount>& settings)
{
    ReplyCheck check = checkReply(Command::GetSramSettings, data, length);
    if (!check.ok()) {
        return check;
    }
    for (unsigned pin = 0; pin < kPinCount; ++pin) {
        settings[pin] = data[kGetSramGpioFirst + pin];
    }
    return {};
}

ReplyCheck readGpioValues(const uint8_t* data, size_t length, GpioValues& values)
{
    ReplyCheck check = checkReply(Command::GetGpioValues, data, length);
    if (!check.ok()) {
        return check;
    }
    GpioValues read;
    for (unsigned pin = 0; pin < kPinCount; ++pin) {
        const uint8_t value = data[kGetGpioFirst + kGetGpioStride * pin];
        const uint8_t direction = data[kGetGpioFirst + kGetGpioStride * pin + 1];
        PinState& state = read.pins[pin];
        if (value == kNotGpioValue || direction == kNotGpioDirection) {
            // Both markers, or neither: one alone is no MCP2221A's answer.
            if (value != kNotGpioValue || direction != kNotGpioDirection) {
                return refused(ReplyError::Inconsistent,
                               fmt::format("the MCP2221A's GET GPIO VALUES says GP{} is a GPIO and is not one "
                                           "(value 0x{:02X}, direction 0x{:02X})",
                                           pin, value, direction));
            }
            continue;
        }
        if (value > 1 || direction > 1) {
            return refused(ReplyError::Inconsistent,
                           fmt::format("the MCP2221A's GET GPIO VALUES gives GP{} the value 0x{:02X} and the "
                                       "direction 0x{:02X}, which are no levels or directions",
                                       pin, value, direction));
        }
        state.gpio = true;
        state.high = value == 1;
        state.output = direction == kDirectionOutput;
    }
    values = read;
    return {};
}

ReplyCheck readSetPinReply(const uint8_t* data, size_t length, unsigned pin)
{
    ReplyCheck check = checkReply(Command::SetGpioOutputValues, data, length);
    if (!check.ok()) {
        return check;
    }
    if (pin >= kPinCount) {
        return refused(ReplyError::Inconsistent, fmt::format("there is no GP{}", pin));
    }
    const size_t at = kSetGpioFirst + kSetGpioStride * pin;
    if (data[at] == kNotGpioValue || data[at + 1] == kNotGpioValue) {
        return refused(ReplyError::NotGpio, fmt::format("GP{} of the MCP2221A is not designated as a GPIO", pin));
    }
    return {};
}

} // namespace hostflash::mcp2221
