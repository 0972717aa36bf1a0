// What the modbus_drive application's control task shares with its console
// command, and the layout of its pages.
#pragma once

#include <stdint.h>

namespace drive {

/// The control task's period.
constexpr uint64_t kPeriodNs = 50'000'000;
/// Cycles without a new page of the drive's values after which the drive
/// counts as not answering: 2.5 s, past a poll's two transmissions of 1 s
/// time-out each, so one slow answer is not taken for a lost drive.
constexpr uint32_t kStaleCycles = 50;
/// The highest speed the controller lets the drive run at, in rpm.
constexpr uint16_t kMaximumSpeedRpm = 3000;
/// The controller's slave address (COM2) and the drive's (COM3).
constexpr uint32_t kControllerUnit = 1;
constexpr uint32_t kDriveUnit = 17;

// "request", written by the plant master through the map.
constexpr uint32_t kRequestSpeedByte = 0; ///< Holding register 0: the speed asked for, rpm.
constexpr uint32_t kRequestRunByte = 2;   ///< Coil 0: run.
// "drive", published by the polling line from the drive's answers.
constexpr uint32_t kDriveSpeedByte = 0;       ///< The drive's input register 0: speed, rpm.
constexpr uint32_t kDriveTemperatureByte = 2; ///< Its input register 1: motor temperature, 0.1 C.
constexpr uint32_t kDriveFlagsByte = 4;       ///< Its discrete input 0: at speed.
// "command", sent to the drive by the polling line.
constexpr uint32_t kCommandSetpointByte = 0; ///< The drive's holding register 0: setpoint, rpm.
constexpr uint32_t kCommandRunByte = 2;      ///< The drive's coil 0: run.
// "process", served to the plant master: input registers 0-2 and discrete inputs 0-1.
constexpr uint32_t kProcessSpeedByte = 0;
constexpr uint32_t kProcessTemperatureByte = 2;
constexpr uint32_t kProcessSetpointByte = 4;
constexpr uint32_t kProcessFlagsByte = 6; ///< Bit 0 at speed, bit 1 the drive answers.

/// What the control task did last; written by it alone, word by word.
struct DriveState {
    volatile uint32_t requested = 0;
    volatile uint32_t run = 0;
    volatile uint32_t setpoint = 0;
    volatile uint32_t speed = 0;
    volatile uint32_t temperature = 0;
    volatile uint32_t atSpeed = 0;
    volatile uint32_t answering = 0;
    volatile uint32_t drivePages = 0; ///< New pages of the drive's values read.
    volatile uint32_t losses = 0;     ///< Times the drive stopped answering.
    volatile uint32_t cycles = 0;
    volatile uint32_t failures = 0;   ///< Refusals of the DSM agent.
    volatile uint32_t lastFailure = 0;
};

extern DriveState state;

} // namespace drive
