// The Microchip MCP2221A's HID commands that drive its GPIO pins, as the
// reset and recovery lines of a controller (docs/guide/flashing.md,
// "Recovery through the reset and strap lines"): the reports, built and
// read, with no I/O. Mcp2221Lines (Mcp2221Lines.hpp) runs them over a
// HidDevice; the fuzz target host_tools/flash/fuzz/fuzz_mcp2221_reports.cpp
// feeds the readers whatever a device might answer.
//
// Facts are from the MCP2221A data sheet (Microchip DS20005565B), section
// 3.1, "Command Set": every command is one 64-byte output report, answered
// by one 64-byte input report whose byte 0 echoes the command code and
// byte 1 is the status, 0x00 when the command completed. Neither report
// carries a report ID.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace hostflash::mcp2221 {

/// Microchip's USB vendor id and the MCP2221/MCP2221A's product id, as the
/// chip enumerates from the factory (DS20005565B, 3.1; Linux's hid-ids.h
/// USB_VENDOR_ID_MICROCHIP, USB_DEVICE_ID_MCP2221).
constexpr uint16_t kVendorId = 0x04D8;
constexpr uint16_t kProductId = 0x00DD;

/// Every report, out and in, is 64 bytes (DS20005565B, 3.1).
constexpr size_t kReportSize = 64;
/// GP0 to GP3.
constexpr unsigned kPinCount = 4;

using Report = std::array<uint8_t, kReportSize>;

/// Command codes, byte 0 of a request and of its reply.
enum class Command : uint8_t {
    StatusSetParameters = 0x10, ///< 3.1.1 STATUS/SET PARAMETERS
    SetGpioOutputValues = 0x50, ///< 3.1.11 SET GPIO OUTPUT VALUES
    GetGpioValues = 0x51,       ///< 3.1.12 GET GPIO VALUES
    SetSramSettings = 0x60,     ///< 3.1.13 SET SRAM SETTINGS
    GetSramSettings = 0x61,     ///< 3.1.14 GET SRAM SETTINGS
};

/// Byte 1 of a reply: the command completed.
constexpr uint8_t kStatusCompleted = 0x00;

// -- SET GPIO OUTPUT VALUES (3.1.11) -----------------------------------------
// Four bytes per pin from byte 2: "alter output" (1: set the value that
// follows), the output value, "alter direction" (1: set the direction that
// follows), the direction. The reply repeats the layout; a pin not
// designated as GPIO answers 0xEE there.
constexpr size_t kSetGpioFirst = 2;
constexpr size_t kSetGpioStride = 4;
/// GPIO direction values (3.1.11, 3.1.12).
constexpr uint8_t kDirectionOutput = 0x00;
constexpr uint8_t kDirectionInput = 0x01;
/// What a pin that is not a GPIO answers instead of its value (3.1.11, 3.1.12).
constexpr uint8_t kNotGpioValue = 0xEE;
/// What it answers instead of its direction (3.1.12).
constexpr uint8_t kNotGpioDirection = 0xEF;

// -- GET GPIO VALUES (3.1.12) --------------------------------------------------
// Two bytes per pin from byte 2: the pin's value, then its direction.
constexpr size_t kGetGpioFirst = 2;
constexpr size_t kGetGpioStride = 2;

// -- SET and GET SRAM SETTINGS (3.1.13, 3.1.14) --------------------------------
/// SET SRAM SETTINGS byte 7: bit 7 set makes the chip take the GP settings
/// of bytes 8 to 11 (all four of them).
constexpr size_t kSetSramAlterGpio = 7;
constexpr uint8_t kAlterGpioConfiguration = 0x80;
constexpr size_t kSetSramGpioFirst = 8;
/// GET SRAM SETTINGS: the GP settings of GP0 to GP3 are bytes 22 to 25.
constexpr size_t kGetSramGpioFirst = 22;
/// A GP setting byte: bit 4 the output value, bit 3 the direction (1
/// input), bits 2-0 the designation, 0 for GPIO.
constexpr uint8_t kGpSettingOutputHigh = 0x10;
constexpr uint8_t kGpSettingInput = 0x08;
constexpr uint8_t kGpSettingDesignationMask = 0x07;
constexpr uint8_t kDesignationGpio = 0x00;

/// Why a reply is not the answer asked for.
enum class ReplyError : uint8_t {
    None,
    Short,        ///< Fewer than 64 bytes came back.
    WrongCommand, ///< Byte 0 is not the command asked.
    Failed,       ///< Byte 1 is not 0x00: the chip did not complete it.
    NotGpio,      ///< The pin asked about is not designated as a GPIO.
    Inconsistent, ///< Values no MCP2221A answers (a direction neither 0 nor 1, say).
};

/// What a reply said, or why it was refused: @p detail then says it in words.
struct ReplyCheck {
    ReplyError error = ReplyError::None;
    std::string detail;

    bool ok() const { return error == ReplyError::None; }
};

/// One pin as GET GPIO VALUES reports it.
struct PinState {
    bool gpio = false;   ///< False: designated for another function.
    bool output = false; ///< Direction output (else input).
    bool high = false;   ///< The pin's level.
};

/// The four pins of a GET GPIO VALUES reply.
struct GpioValues {
    std::array<PinState, kPinCount> pins{};
};

/// A command's name and code, for messages: "SET GPIO OUTPUT VALUES (0x50)".
std::string commandText(Command command);

/// A request with only its command code set (every other byte 0, which
/// changes nothing in every command used here).
Report request(Command command);

/// SET GPIO OUTPUT VALUES: drive @p pin (0 to 3) to @p high; with
/// @p makeOutput also make it an output in the same report.
Report setPin(unsigned pin, bool high, bool makeOutput);

/// SET SRAM SETTINGS: the GP settings @p settings (bytes 22 to 25 of GET
/// SRAM SETTINGS, GP0 first) with @p outputPins (a bit per pin) made GPIO
/// outputs driven high (released), the other pins as they were. Only the
/// GP settings change: bytes 2 to 6 keep their "alter" bits clear.
Report setGpioDesignations(const std::array<uint8_t, kPinCount>& settings, uint8_t outputPins);

/// Checks the common part of a reply to @p command: 64 bytes, the command
/// echoed, the status completed.
ReplyCheck checkReply(Command command, const uint8_t* data, size_t length);

/// Reads a GET SRAM SETTINGS reply: the four GP settings into @p settings.
ReplyCheck readSramGpioSettings(const uint8_t* data, size_t length, std::array<uint8_t, kPinCount>& settings);

/// Reads a GET GPIO VALUES reply into @p values. Every pin is read; a pin
/// that is not a GPIO is reported with gpio false, which is not an error
/// here (pinState() says so for the pin asked about).
ReplyCheck readGpioValues(const uint8_t* data, size_t length, GpioValues& values);

/// Reads a SET GPIO OUTPUT VALUES reply to a request that altered @p pin:
/// refused with NotGpio when the chip says the pin is not a GPIO.
ReplyCheck readSetPinReply(const uint8_t* data, size_t length, unsigned pin);

} // namespace hostflash::mcp2221
