// Why the Modbus stack refused a configuration, a request or a response.
//
// The stack has two kinds of failure and keeps them apart: a Modbus
// *exception* is a valid answer of a server ([AP] 7, ExceptionCode in
// Protocol.hpp) and travels on the wire, while a ModbusError is what this
// side found wrong: a request it cannot build, a response that does not match
// the request, a time-out. A master reports an exception response as
// ModbusError::ExceptionResponse together with the server's ExceptionCode.
//
// Errors are values, never exceptions: the same code runs in the freestanding
// firmware, built with -fno-exceptions. The numeric values are stable so that
// counters and logs keep their meaning; new reasons take new values.
#pragma once

#include <dcos/Status.hpp>

#include <stdint.h>

namespace modbus {

enum class ModbusError : uint8_t {
    Ok = 0,

    // Configuration and arguments.
    InvalidConfiguration = 1,  ///< A baud rate, character format or time-out out of its documented range.
    InvalidArgument = 2,       ///< A missing buffer or an argument out of range.
    InvalidSlaveAddress = 3,   ///< A unit address outside 0..247, or 0 where a slave is needed.
    InvalidQuantity = 4,       ///< A quantity outside the limits of its function code ([AP] 6).
    AddressOverflow = 5,       ///< Start address plus quantity runs past 0xFFFF.
    InvalidCoilValue = 6,      ///< A single-coil value other than 0x0000 and 0xFF00.
    FrameTooLong = 7,          ///< A PDU above 253 bytes or an ADU above 256 bytes.
    BufferTooSmall = 8,        ///< The output buffer cannot hold the result.

    // A master's transaction.
    Busy = 9,                  ///< A transaction is already in progress.
    NotExpected = 10,          ///< A confirmation or call the state machine was not waiting for.
    Timeout = 11,              ///< No response within the response time-out, after every retry.
    ExceptionResponse = 12,    ///< The server answered with an exception; its code comes with it.
    UnexpectedFunction = 13,   ///< The response carries another function code than the request.
    InvalidResponse = 14,      ///< The response's length or byte count does not fit the request.
    EchoMismatch = 15,         ///< A write response does not echo the request's address, quantity or value.
    InvalidException = 16,     ///< An exception response without exactly one exception code byte.
};

/// A short, stable English name for @p error, for logs and the console.
const char* modbusErrorName(ModbusError error);

/// A short, stable English name for an exception code ([AP] 7), or
/// "unknown exception" for a code the specification does not define.
const char* exceptionName(uint8_t code);

/// The kernel status a service reports for @p error: Timeout for a time-out,
/// Busy for a transaction in progress, NoMemory for a buffer too small, and
/// InvalidArgument for everything the caller or the peer got wrong.
dcos::Status toStatus(ModbusError error);

} // namespace modbus
