#include <bsp/Rtc146818.hpp>

#include <dcos/GregorianCalendar.hpp>

namespace bsp {

namespace {

uint8_t fromBcd(uint8_t value) { return static_cast<uint8_t>((value >> 4) * 10 + (value & 0x0F)); }

bool isBcd(uint8_t value) { return (value & 0x0F) <= 9 && (value >> 4) <= 9; }

} // namespace

uint8_t Rtc146818::readRegister(uint8_t index) const
{
    // Bit 7 of the index port gates NMI on the PC; it stays clear (NMI on).
    window_.write8(indexRegister, static_cast<uint8_t>(index & 0x7F));
    return window_.read8(dataRegister);
}

bool Rtc146818::waitForUpdateToEnd() const
{
    for (unsigned poll = 0; poll < kUpdateWaitPolls; ++poll) {
        if ((readRegister(registerA) & updateInProgress) == 0) {
            return true;
        }
    }
    return false;
}

Rtc146818::RawTime Rtc146818::readRaw() const
{
    return RawTime{readRegister(secondsIndex), readRegister(minutesIndex),    readRegister(hoursIndex),
                   readRegister(dayOfMonthIndex), readRegister(monthIndex), readRegister(yearIndex),
                   readRegister(centuryIndex)};
}

dcos::Result<dcos::DateTime> Rtc146818::read() const
{
    // An update may begin right after UIP was seen clear: read until two
    // reads, each after the update flag cleared, agree.
    RawTime raw{};
    bool consistent = false;
    for (unsigned attempt = 0; attempt < kConsistentReadTries && !consistent; ++attempt) {
        if (!waitForUpdateToEnd()) {
            return dcos::Status::Busy;
        }
        raw = readRaw();
        if (!waitForUpdateToEnd()) {
            return dcos::Status::Busy;
        }
        consistent = readRaw() == raw;
    }
    if (!consistent) {
        return dcos::Status::Busy;
    }
    const uint8_t format = readRegister(registerB);
    const bool pm = (format & twentyFourHour) == 0 && (raw.hour & hourPm) != 0;
    uint8_t hour = static_cast<uint8_t>(raw.hour & ~hourPm);
    if ((format & binaryMode) == 0) {
        const uint8_t bytes[] = {raw.second, raw.minute, hour, raw.day, raw.month, raw.year};
        for (const uint8_t byte : bytes) {
            if (!isBcd(byte)) {
                return dcos::Status::Corrupted;
            }
        }
        raw.second = fromBcd(raw.second);
        raw.minute = fromBcd(raw.minute);
        hour = fromBcd(hour);
        raw.day = fromBcd(raw.day);
        raw.month = fromBcd(raw.month);
        raw.year = fromBcd(raw.year);
        raw.century = isBcd(raw.century) ? fromBcd(raw.century) : 0;
    }
    if ((format & twentyFourHour) == 0) {
        // 12-hour format: 12 AM is midnight, 12 PM is noon.
        if (hour < 1 || hour > 12) {
            return dcos::Status::Corrupted;
        }
        hour = static_cast<uint8_t>(hour % 12 + (pm ? 12 : 0));
    }
    // A century byte outside 19..29 is taken as absent (not every board
    // keeps one): the years 2000-2099 are assumed then.
    const unsigned century = raw.century >= 19 && raw.century <= 29 ? raw.century : 20;
    dcos::DateTime time{};
    time.year = static_cast<uint16_t>(century * 100 + raw.year);
    time.month = raw.month;
    time.day = raw.day;
    time.hour = hour;
    time.minute = raw.minute;
    time.second = raw.second;
    if (raw.year > 99 || dcos::GregorianCalendar::validate(time) != dcos::Status::Ok) {
        return dcos::Status::Corrupted;
    }
    return time;
}

} // namespace bsp
