#include <modbus/Request.hpp>
#include <modbus/Wire.hpp>

namespace modbus {

namespace {

ModbusError checkUnit(uint8_t unit, bool broadcastAllowed)
{
    if (unit > kMaxSlaveAddress || (unit == kBroadcastAddress && !broadcastAllowed)) {
        return ModbusError::InvalidSlaveAddress;
    }
    return ModbusError::Ok;
}

ModbusError checkRange(uint16_t address, uint16_t quantity, uint16_t maximum)
{
    if (quantity < 1 || quantity > maximum) {
        return ModbusError::InvalidQuantity;
    }
    if (static_cast<uint32_t>(address) + quantity > 0x10000) {
        return ModbusError::AddressOverflow;
    }
    return ModbusError::Ok;
}

// The five-byte form shared by functions 01 to 06: function, address, and a
// quantity or a value.
Request addressed(uint8_t unit, FunctionCode function, uint16_t address, uint16_t second)
{
    Request request;
    request.unit = unit;
    request.pdu[0] = static_cast<uint8_t>(function);
    writeU16(request.pdu + 1, address);
    writeU16(request.pdu + 3, second);
    request.length = 5;
    return request;
}

ModbusResult<Request> read(uint8_t unit, FunctionCode function, uint16_t address, uint16_t quantity,
                           uint16_t maximum)
{
    ModbusError error = checkUnit(unit, false);
    if (error == ModbusError::Ok) {
        error = checkRange(address, quantity, maximum);
    }
    if (error != ModbusError::Ok) {
        return error;
    }
    return addressed(unit, function, address, quantity);
}

} // namespace

ModbusResult<Request> Request::readCoils(uint8_t unit, uint16_t address, uint16_t quantity)
{
    return read(unit, FunctionCode::ReadCoils, address, quantity, kMaxReadBits);
}

ModbusResult<Request> Request::readDiscreteInputs(uint8_t unit, uint16_t address, uint16_t quantity)
{
    return read(unit, FunctionCode::ReadDiscreteInputs, address, quantity, kMaxReadBits);
}

ModbusResult<Request> Request::readHoldingRegisters(uint8_t unit, uint16_t address, uint16_t quantity)
{
    return read(unit, FunctionCode::ReadHoldingRegisters, address, quantity, kMaxReadRegisters);
}

ModbusResult<Request> Request::readInputRegisters(uint8_t unit, uint16_t address, uint16_t quantity)
{
    return read(unit, FunctionCode::ReadInputRegisters, address, quantity, kMaxReadRegisters);
}

ModbusResult<Request> Request::writeSingleCoil(uint8_t unit, uint16_t address, bool on)
{
    const ModbusError error = checkUnit(unit, true);
    if (error != ModbusError::Ok) {
        return error;
    }
    return addressed(unit, FunctionCode::WriteSingleCoil, address, on ? kCoilOn : kCoilOff);
}

ModbusResult<Request> Request::writeSingleRegister(uint8_t unit, uint16_t address, uint16_t value)
{
    const ModbusError error = checkUnit(unit, true);
    if (error != ModbusError::Ok) {
        return error;
    }
    return addressed(unit, FunctionCode::WriteSingleRegister, address, value);
}

ModbusResult<Request> Request::writeMultipleCoils(uint8_t unit, uint16_t address, uint16_t quantity,
                                                  const uint8_t* bits)
{
    ModbusError error = checkUnit(unit, true);
    if (error == ModbusError::Ok) {
        error = checkRange(address, quantity, kMaxWriteCoils);
    }
    if (error == ModbusError::Ok && bits == nullptr) {
        error = ModbusError::InvalidArgument;
    }
    if (error != ModbusError::Ok) {
        return error;
    }
    Request request = addressed(unit, FunctionCode::WriteMultipleCoils, address, quantity);
    const size_t byteCount = bitBytes(quantity);
    request.pdu[5] = static_cast<uint8_t>(byteCount);
    for (size_t i = 0; i < byteCount; ++i) {
        request.pdu[6 + i] = 0;
    }
    // Only the bits asked for are copied; the rest of the last byte is zero,
    // as a server sends it in a read ([AP] 6.11 leaves it unused).
    for (size_t i = 0; i < quantity; ++i) {
        if (((bits[i / 8] >> (i % 8)) & 1) != 0) {
            request.pdu[6 + i / 8] = static_cast<uint8_t>(request.pdu[6 + i / 8] | (1u << (i % 8)));
        }
    }
    request.length = static_cast<uint8_t>(6 + byteCount);
    return request;
}

ModbusResult<Request> Request::writeMultipleRegisters(uint8_t unit, uint16_t address, uint16_t quantity,
                                                      const uint16_t* values)
{
    ModbusError error = checkUnit(unit, true);
    if (error == ModbusError::Ok) {
        error = checkRange(address, quantity, kMaxWriteRegisters);
    }
    if (error == ModbusError::Ok && values == nullptr) {
        error = ModbusError::InvalidArgument;
    }
    if (error != ModbusError::Ok) {
        return error;
    }
    Request request = addressed(unit, FunctionCode::WriteMultipleRegisters, address, quantity);
    request.pdu[5] = static_cast<uint8_t>(2 * quantity);
    for (size_t i = 0; i < quantity; ++i) {
        writeU16(request.pdu + 6 + 2 * i, values[i]);
    }
    request.length = static_cast<uint8_t>(6 + 2 * quantity);
    return request;
}

ModbusResult<Request> Request::readWriteMultipleRegisters(uint8_t unit, uint16_t readAddress, uint16_t readQuantity,
                                                          uint16_t writeAddress, uint16_t writeQuantity,
                                                          const uint16_t* values)
{
    ModbusError error = checkUnit(unit, false);
    if (error == ModbusError::Ok) {
        error = checkRange(readAddress, readQuantity, kMaxReadWriteReadRegisters);
    }
    if (error == ModbusError::Ok) {
        error = checkRange(writeAddress, writeQuantity, kMaxReadWriteWriteRegisters);
    }
    if (error == ModbusError::Ok && values == nullptr) {
        error = ModbusError::InvalidArgument;
    }
    if (error != ModbusError::Ok) {
        return error;
    }
    Request request = addressed(unit, FunctionCode::ReadWriteMultipleRegisters, readAddress, readQuantity);
    writeU16(request.pdu + 5, writeAddress);
    writeU16(request.pdu + 7, writeQuantity);
    request.pdu[9] = static_cast<uint8_t>(2 * writeQuantity);
    for (size_t i = 0; i < writeQuantity; ++i) {
        writeU16(request.pdu + 10 + 2 * i, values[i]);
    }
    request.length = static_cast<uint8_t>(10 + 2 * writeQuantity);
    return request;
}

ModbusResult<Request> Request::readDeviceIdentification(uint8_t unit, DeviceIdCode code, uint8_t objectId)
{
    const ModbusError error = checkUnit(unit, false);
    if (error != ModbusError::Ok) {
        return error;
    }
    const uint8_t raw = static_cast<uint8_t>(code);
    if (raw < static_cast<uint8_t>(DeviceIdCode::BasicStream) || raw > static_cast<uint8_t>(DeviceIdCode::Individual)) {
        return ModbusError::InvalidArgument;
    }
    Request request;
    request.unit = unit;
    request.pdu[0] = static_cast<uint8_t>(FunctionCode::EncapsulatedInterface);
    request.pdu[1] = kMeiReadDeviceIdentification;
    request.pdu[2] = raw;
    request.pdu[3] = objectId;
    request.length = 4;
    return request;
}

ModbusError checkResponse(const Request& request, const uint8_t* pdu, size_t length, ExceptionCode& exception)
{
    exception = ExceptionCode::None;
    if (pdu == nullptr || length == 0) {
        return ModbusError::InvalidResponse;
    }
    const uint8_t function = request.function();
    if (pdu[0] == (function | kExceptionFlag)) {
        if (length != 2) {
            return ModbusError::InvalidException;
        }
        exception = static_cast<ExceptionCode>(pdu[1]);
        return ModbusError::ExceptionResponse;
    }
    if (pdu[0] != function) {
        return ModbusError::UnexpectedFunction;
    }
    const uint16_t quantity = readU16(request.pdu + 3);
    switch (static_cast<FunctionCode>(function)) {
    case FunctionCode::ReadCoils:
    case FunctionCode::ReadDiscreteInputs: {
        const size_t byteCount = bitBytes(quantity);
        return length == 2 + byteCount && pdu[1] == byteCount ? ModbusError::Ok : ModbusError::InvalidResponse;
    }
    case FunctionCode::ReadHoldingRegisters:
    case FunctionCode::ReadInputRegisters:
    case FunctionCode::ReadWriteMultipleRegisters: {
        // For 17 the read quantity sits where the other reads keep theirs.
        const size_t byteCount = 2 * static_cast<size_t>(quantity);
        return length == 2 + byteCount && pdu[1] == byteCount ? ModbusError::Ok : ModbusError::InvalidResponse;
    }
    case FunctionCode::WriteSingleCoil:
    case FunctionCode::WriteSingleRegister:
    case FunctionCode::WriteMultipleCoils:
    case FunctionCode::WriteMultipleRegisters:
        if (length != 5) {
            return ModbusError::InvalidResponse;
        }
        for (size_t i = 1; i < 5; ++i) {
            if (pdu[i] != request.pdu[i]) {
                return ModbusError::EchoMismatch;
            }
        }
        return ModbusError::Ok;
    case FunctionCode::EncapsulatedInterface: {
        if (length < kDeviceIdHeaderLength || pdu[1] != request.pdu[1] || pdu[2] != request.pdu[2]
            || (pdu[4] != 0 && pdu[4] != kMoreFollows)) {
            return ModbusError::InvalidResponse;
        }
        // The objects must fill the PDU exactly, each within it.
        size_t position = kDeviceIdHeaderLength;
        for (size_t i = 0; i < pdu[6]; ++i) {
            if (position + 2 > length || position + 2 + pdu[position + 1] > length) {
                return ModbusError::InvalidResponse;
            }
            position += 2 + pdu[position + 1];
        }
        return position == length ? ModbusError::Ok : ModbusError::InvalidResponse;
    }
    }
    // A request filled in by hand with a function this stack does not build
    // cannot have its response checked.
    return ModbusError::InvalidArgument;
}

} // namespace modbus
