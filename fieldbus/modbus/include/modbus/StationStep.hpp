// What one input did to a station (Slave, Master): the bytes to put on the
// line, and for a master the end of a transaction.
//
// The stations own no UART and no timer: the caller feeds them received
// bytes, "transmit done" confirmations and the time, and each call answers
// with a step. The fields are independent: one poll can end a transaction
// and start the retry of another.
#pragma once

#include <modbus/ModbusError.hpp>
#include <modbus/Protocol.hpp>

#include <stddef.h>
#include <stdint.h>

namespace modbus {

struct StationStep {
    /// Hand these bytes (a whole ADU) to the line now, then call the
    /// station's onTransmitDone() once the last one has left the UART. They
    /// stay valid until then.
    const uint8_t* transmit = nullptr;
    size_t transmitLength = 0;
    /// A master's transaction ended: with Ok (a response, or a broadcast
    /// after its turnaround delay), ExceptionResponse and the exception code,
    /// or the error that ended it after every retry.
    bool completed = false;
    ModbusError error = ModbusError::Ok;
    ExceptionCode exception = ExceptionCode::None;
    /// Why this call was refused (Busy, NotExpected, a request the transport
    /// cannot frame); Ok when it was taken.
    ModbusError rejected = ModbusError::Ok;
};

} // namespace modbus
