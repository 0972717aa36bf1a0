// A client request: the unit it goes to and its PDU, built and checked
// against the limits of [AP] 6 before anything reaches the line, so a master
// never sends a request a conforming server must refuse for its form.
//
// A request is a plain value with its PDU inside (no pointers to the
// caller's data), so a polling table holds its requests in static storage.
#pragma once

#include <modbus/ModbusResult.hpp>
#include <modbus/Protocol.hpp>

#include <stddef.h>
#include <stdint.h>

namespace modbus {

struct Request {
    uint8_t unit = 0;                   ///< The slave address, 0 for a broadcast write.
    uint8_t length = 0;                 ///< Bytes of the PDU.
    uint8_t pdu[kMaxPduLength] = {};    ///< The function code and its data.

    /// The function code.
    uint8_t function() const { return pdu[0]; }
    /// Whether it goes to every slave and gets no response.
    bool isBroadcast() const { return unit == kBroadcastAddress; }

    // Every builder refuses a unit above 247 and, for a read, the broadcast
    // address 0 (InvalidSlaveAddress); a quantity outside the limits of its
    // function code (InvalidQuantity); a range past 0xFFFF (AddressOverflow);
    // and missing data (InvalidArgument).

    /// Function 01, @p quantity 1..2000 coils from @p address ([AP] 6.1).
    static ModbusResult<Request> readCoils(uint8_t unit, uint16_t address, uint16_t quantity);
    /// Function 02, @p quantity 1..2000 discrete inputs ([AP] 6.2).
    static ModbusResult<Request> readDiscreteInputs(uint8_t unit, uint16_t address, uint16_t quantity);
    /// Function 03, @p quantity 1..125 holding registers ([AP] 6.3).
    static ModbusResult<Request> readHoldingRegisters(uint8_t unit, uint16_t address, uint16_t quantity);
    /// Function 04, @p quantity 1..125 input registers ([AP] 6.4).
    static ModbusResult<Request> readInputRegisters(uint8_t unit, uint16_t address, uint16_t quantity);
    /// Function 05, one coil on (FF00) or off (0000) ([AP] 6.5).
    static ModbusResult<Request> writeSingleCoil(uint8_t unit, uint16_t address, bool on);
    /// Function 06, one holding register ([AP] 6.6).
    static ModbusResult<Request> writeSingleRegister(uint8_t unit, uint16_t address, uint16_t value);
    /// Function 0F, @p quantity 1..1968 coils from the packed @p bits ([AP] 6.11).
    static ModbusResult<Request> writeMultipleCoils(uint8_t unit, uint16_t address, uint16_t quantity,
                                                    const uint8_t* bits);
    /// Function 10, @p quantity 1..123 holding registers from @p values ([AP] 6.12).
    static ModbusResult<Request> writeMultipleRegisters(uint8_t unit, uint16_t address, uint16_t quantity,
                                                        const uint16_t* values);
    /// Function 17: writes @p writeQuantity 1..121 registers, then reads
    /// @p readQuantity 1..125 ([AP] 6.17); never broadcast.
    static ModbusResult<Request> readWriteMultipleRegisters(uint8_t unit, uint16_t readAddress,
                                                            uint16_t readQuantity, uint16_t writeAddress,
                                                            uint16_t writeQuantity, const uint16_t* values);
    /// Function 2B / 0E, Read Device Identification from @p objectId ([AP] 6.21);
    /// InvalidArgument for a code outside 01..04.
    static ModbusResult<Request> readDeviceIdentification(uint8_t unit, DeviceIdCode code, uint8_t objectId);
};

/// Checks the response PDU at @p pdu (@p length bytes) against @p request, as
/// a master must before using it ([SL] 2.4.1, "processing of the reply"):
///   - the request's function with 0x80 set and exactly one code byte is an
///     exception response: ExceptionResponse, with the code in @p exception
///     (InvalidException when the length is not 2);
///   - another function code: UnexpectedFunction;
///   - reads: a byte count matching the quantity and the PDU length
///     (InvalidResponse);
///   - writes: the echo of address and quantity or value (EchoMismatch);
///   - Read Device Identification: MEI type, code, and objects that fill the
///     PDU exactly (InvalidResponse).
/// InvalidArgument for a request with a function code this stack does not
/// build. @p exception is set to None for every result but ExceptionResponse.
ModbusError checkResponse(const Request& request, const uint8_t* pdu, size_t length, ExceptionCode& exception);

} // namespace modbus
