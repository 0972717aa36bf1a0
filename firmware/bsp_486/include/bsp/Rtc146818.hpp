// Driver for the real-time clock of a PC-compatible board: the Motorola
// MC146818 (or a compatible part such as the DS12887), behind the index and
// data ports 0x70 and 0x71.
//
// Register and bit names follow the MC146818A datasheet, "Address Map"
// (Figure 3) and "Register A" to "Register D". The century byte at index
// 0x32 is the IBM PC/AT convention, not part of the chip.
#pragma once

#include <dcos/DateTime.hpp>
#include <dcos/Status.hpp>

#include <arch_x86/IoWindow.hpp>

#include <stdint.h>

namespace bsp {

class Rtc146818 {
public:
    // Port offsets within the two-port window.
    static constexpr uint8_t indexRegister = 0;
    static constexpr uint8_t dataRegister = 1;

    // Time and calendar bytes (datasheet, Figure 3 "Address Map").
    static constexpr uint8_t secondsIndex = 0x00;
    static constexpr uint8_t minutesIndex = 0x02;
    static constexpr uint8_t hoursIndex = 0x04;
    static constexpr uint8_t dayOfMonthIndex = 0x07;
    static constexpr uint8_t monthIndex = 0x08;
    static constexpr uint8_t yearIndex = 0x09;
    static constexpr uint8_t registerA = 0x0A;
    static constexpr uint8_t registerB = 0x0B;
    /// The century, in the same format as the year (IBM PC/AT CMOS map).
    static constexpr uint8_t centuryIndex = 0x32;

    /// Register A: UIP, an update of the time bytes is in progress or due
    /// within 244 us ("Update Cycle"); they are not to be read meanwhile.
    static constexpr uint8_t updateInProgress = 1u << 7;
    /// Register B: DM, data mode binary (1) or BCD (0).
    static constexpr uint8_t binaryMode = 1u << 2;
    /// Register B: 24/12, hours in 24-hour (1) or 12-hour (0) format.
    static constexpr uint8_t twentyFourHour = 1u << 1;
    /// The hours byte in 12-hour format: PM flag (bit 7).
    static constexpr uint8_t hourPm = 1u << 7;

    /// How often a read waits for UIP to clear before giving up. An update
    /// takes under 2 ms; each poll is a port access of about 1 us.
    static constexpr unsigned kUpdateWaitPolls = 10000;
    /// How often the bytes are read again until two reads agree.
    static constexpr unsigned kConsistentReadTries = 4;

    explicit Rtc146818(arch_x86::IoWindow window) : window_(window) {}

    /// Reads the time of day. Busy when the chip never leaves its update
    /// cycle or the bytes keep changing; Corrupted when they do not form a
    /// valid date and time (a clock never set, or a dead battery).
    dcos::Result<dcos::DateTime> read() const;

private:
    struct RawTime {
        uint8_t second, minute, hour, day, month, year, century;
        bool operator==(const RawTime&) const = default;
    };

    uint8_t readRegister(uint8_t index) const;
    bool waitForUpdateToEnd() const;
    RawTime readRaw() const;

    arch_x86::IoWindow window_;
};

} // namespace bsp
