#include <modbus/ModbusError.hpp>
#include <modbus/Protocol.hpp>

namespace modbus {

const char* modbusErrorName(ModbusError error)
{
    switch (error) {
    case ModbusError::Ok: return "ok";
    case ModbusError::InvalidConfiguration: return "invalid configuration";
    case ModbusError::InvalidArgument: return "invalid argument";
    case ModbusError::InvalidSlaveAddress: return "invalid slave address";
    case ModbusError::InvalidQuantity: return "invalid quantity";
    case ModbusError::AddressOverflow: return "address overflow";
    case ModbusError::InvalidCoilValue: return "invalid coil value";
    case ModbusError::FrameTooLong: return "frame too long";
    case ModbusError::BufferTooSmall: return "buffer too small";
    case ModbusError::Busy: return "busy";
    case ModbusError::NotExpected: return "not expected";
    case ModbusError::Timeout: return "response time-out";
    case ModbusError::ExceptionResponse: return "exception response";
    case ModbusError::UnexpectedFunction: return "unexpected function code";
    case ModbusError::InvalidResponse: return "invalid response";
    case ModbusError::EchoMismatch: return "echo mismatch";
    case ModbusError::InvalidException: return "invalid exception response";
    }
    return "unknown modbus error";
}

const char* exceptionName(uint8_t code)
{
    switch (static_cast<ExceptionCode>(code)) {
    case ExceptionCode::None: return "none";
    case ExceptionCode::IllegalFunction: return "illegal function";
    case ExceptionCode::IllegalDataAddress: return "illegal data address";
    case ExceptionCode::IllegalDataValue: return "illegal data value";
    case ExceptionCode::ServerDeviceFailure: return "server device failure";
    case ExceptionCode::Acknowledge: return "acknowledge";
    case ExceptionCode::ServerDeviceBusy: return "server device busy";
    case ExceptionCode::MemoryParityError: return "memory parity error";
    case ExceptionCode::GatewayPathUnavailable: return "gateway path unavailable";
    case ExceptionCode::GatewayTargetFailed: return "gateway target failed to respond";
    }
    return "unknown exception";
}

dcos::Status toStatus(ModbusError error)
{
    switch (error) {
    case ModbusError::Ok:
        return dcos::Status::Ok;
    case ModbusError::Timeout:
        return dcos::Status::Timeout;
    case ModbusError::Busy:
        return dcos::Status::Busy;
    case ModbusError::BufferTooSmall:
        return dcos::Status::NoMemory;
    case ModbusError::InvalidConfiguration:
    case ModbusError::InvalidArgument:
    case ModbusError::InvalidSlaveAddress:
    case ModbusError::InvalidQuantity:
    case ModbusError::AddressOverflow:
    case ModbusError::InvalidCoilValue:
    case ModbusError::FrameTooLong:
    case ModbusError::NotExpected:
    case ModbusError::ExceptionResponse:
    case ModbusError::UnexpectedFunction:
    case ModbusError::InvalidResponse:
    case ModbusError::EchoMismatch:
    case ModbusError::InvalidException:
        return dcos::Status::InvalidArgument;
    }
    return dcos::Status::InvalidArgument;
}

} // namespace modbus
