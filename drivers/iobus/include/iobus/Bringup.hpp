// The controller's half of the I/O board bring-up (issue 5, item 5).
//
// runBringup prints exactly the lines of docs/iobus/bringup-protocol.md,
// each starting with `BRINGUP`, for the host tool (host_tools/bringup/) to
// parse and judge. The console command `iobus bringup` calls it; a task
// with the board installed may call it too.
#pragma once

#include <iobus/MfioBoard.hpp>

#include <runtime/Format.hpp>

#include <stdint.h>

namespace iobus {

/// How thorough the sequence is.
struct BringupSettings {
    /// Conversions averaged per DAC step (at least 2 for a noise estimate;
    /// at most 10^5, which keeps the pooled noise's sums within 64 bits).
    unsigned samplesPerPoint = 8;
    /// The most DAC steps per channel and gain (odd, so 0 V is a step).
    unsigned maximumPoints = 9;
    /// Margin, in ADC codes, kept from either end of the converter's range
    /// so that noise does not saturate the extreme steps.
    unsigned marginCodes = 48;
    /// Interrupt-driven conversions of the `IRQ` step.
    unsigned interruptConversions = 64;
    /// How long the `IRQ` step waits for each interrupt.
    uint64_t interruptTimeoutNs = 10000000;
};

/// Runs the steps after `BRINGUP PROBE ok` on the installed board @p board
/// (its id @p id), which the caller has opened: the firmware's identity
/// (`BRINGUP FIRMWARE`), DIO walking ones and zeros, ADC linearity and noise
/// (the largest per-point deviation and the sweep's pooled estimate with its
/// degrees of freedom) for every channel and gain, and interrupt delivery.
/// Prints one `BRINGUP` line per result to @p out and returns the number of steps
/// that could not run or found a stuck or absent signal. Leaves every DAC
/// at 0 V, the outputs low, every gain at 1 and the board in interrupt mode.
unsigned runBringupSteps(runtime::CharacterSink& out, dcos::ObjectId id, const BringupSettings& settings);

} // namespace iobus
