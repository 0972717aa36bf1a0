// A value or the ModbusError that explains why there is none: the Modbus
// stack's counterpart of dcos::Result<T> and can::LinkResult<T>, the same
// shape so that code moving between them reads the same.
#pragma once

#include <modbus/ModbusError.hpp>

namespace modbus {

template <typename T>
class [[nodiscard]] ModbusResult {
public:
    constexpr ModbusResult(T value) : value_(value), error_(ModbusError::Ok) {}
    constexpr ModbusResult(ModbusError error) : value_(), error_(error) {}

    /// Whether there is a value.
    constexpr bool ok() const { return error_ == ModbusError::Ok; }
    /// Why there is no value; Ok when there is one.
    constexpr ModbusError error() const { return error_; }
    /// The value; only meaningful when ok() is true.
    constexpr const T& value() const { return value_; }

private:
    T value_;
    ModbusError error_;
};

} // namespace modbus
