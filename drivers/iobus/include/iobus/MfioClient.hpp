// Task-side helpers for the multi-function I/O board.
//
// The driver never waits (dcos/Device.hpp), so an interrupt-driven
// conversion takes two Reads with a wait between them. These functions do
// that for a task: they call the board only through the system agent, wait
// for the driver's conversion event with a time-out, and so work from any
// task, with or without super-user privilege, on an open board.
#pragma once

#include <iobus/AnalogScaling.hpp>
#include <iobus/MfioBoard.hpp>

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace iobus {

/// Converts analog input @p input (0-7) and returns the `ADC_DATA` word
/// (bits 11:0 the code, bit 15 overrange). Must run in a task.
///
/// In interrupt mode it starts the conversion, waits for the driver's
/// conversion event (MfioBoard::kDefaultConversionEvent unless the caller
/// set another with kSetConversionEvent, passed here as @p event) for at
/// most @p timeoutNs (0: the driver's interrupt bound plus a tick), and
/// reads the result; if the interrupt never comes the driver collects the
/// result by polling. Fails with the system agent's or the driver's status,
/// Timeout when no result came, or InInterrupt in an interrupt handler.
dcos::Result<uint16_t> readAnalogInput(dcos::ObjectId board, unsigned input, uint64_t timeoutNs = 0,
                                       uint32_t event = MfioBoard::kDefaultConversionEvent);

/// Converts analog input @p input and scales it at the input's current gain.
dcos::Result<AnalogValue> readAnalogInputMicrovolts(dcos::ObjectId board, unsigned input);

/// Sets the gain of analog input @p input to @p factor (1, 10, 100 or 1000).
dcos::Status setGain(dcos::ObjectId board, unsigned input, uint32_t factor);

/// Reads a 16-bit channel that needs no conversion (AO read-back, DI, DO).
dcos::Result<uint16_t> readWord(dcos::ObjectId board, uint32_t channel);

/// Writes a 16-bit channel (an AO code, or the DO word).
dcos::Status writeWord(dcos::ObjectId board, uint32_t channel, uint16_t value);

} // namespace iobus
