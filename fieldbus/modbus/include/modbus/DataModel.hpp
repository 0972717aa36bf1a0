// The data a slave serves, behind the interface its application implements
// ([AP] 4.3: coils, discrete inputs, input registers, holding registers).
//
// The stack owns no data: Server checks a request's form (quantities, byte
// counts, values) and then asks the model, which decides which addresses
// exist and what they hold. Each call answers ExceptionCode::None or the
// exception the server sends back: IllegalDataAddress for an address range
// the model does not have, ServerDeviceFailure when it cannot do what was
// asked (a sensor that does not answer, a value the process refuses). The
// server has checked that address + quantity does not run past 0xFFFF and
// that quantity is within the limits of the function code, so a model only
// checks its own ranges.
//
// Bits travel packed as on the wire ([AP] 6.1): the bit at `address` is bit 0
// of byte 0, the next bit 1, and so on; getBit() and setBit() read and write
// one. A read must set every bit of the bytes it covers that lies past the
// quantity to 0 ([AP] 6.1: "padded with zeros"); the server clears them
// before the call, so a model that only sets bits need not care.
//
// The calls run in the context that feeds the stack; a model whose data is
// shared with control tasks protects it the way those tasks do.
#pragma once

#include <modbus/Protocol.hpp>

#include <stddef.h>
#include <stdint.h>

namespace modbus {

/// Bit @p index of the packed bits at @p bytes.
inline bool getBit(const uint8_t* bytes, size_t index)
{
    return ((bytes[index / 8] >> (index % 8)) & 1) != 0;
}

/// Sets bit @p index of the packed bits at @p bytes to @p value.
inline void setBit(uint8_t* bytes, size_t index, bool value)
{
    const uint8_t mask = static_cast<uint8_t>(1u << (index % 8));
    bytes[index / 8] = static_cast<uint8_t>(value ? (bytes[index / 8] | mask) : (bytes[index / 8] & ~mask));
}

class DataModel {
public:
    /// Reads @p quantity coils from @p address into @p bits, packed (function 01).
    virtual ExceptionCode readCoils(uint16_t address, uint16_t quantity, uint8_t* bits) = 0;
    /// Reads @p quantity discrete inputs from @p address into @p bits, packed (function 02).
    virtual ExceptionCode readDiscreteInputs(uint16_t address, uint16_t quantity, uint8_t* bits) = 0;
    /// Reads @p quantity holding registers from @p address (functions 03 and 17).
    virtual ExceptionCode readHoldingRegisters(uint16_t address, uint16_t quantity, uint16_t* values) = 0;
    /// Reads @p quantity input registers from @p address (function 04).
    virtual ExceptionCode readInputRegisters(uint16_t address, uint16_t quantity, uint16_t* values) = 0;
    /// Writes @p quantity coils from @p bits, packed, at @p address (functions 05 and 0F).
    virtual ExceptionCode writeCoils(uint16_t address, uint16_t quantity, const uint8_t* bits) = 0;
    /// Writes @p quantity holding registers at @p address (functions 06, 10 and 17).
    virtual ExceptionCode writeHoldingRegisters(uint16_t address, uint16_t quantity, const uint16_t* values) = 0;

protected:
    ~DataModel() = default;
};

} // namespace modbus
