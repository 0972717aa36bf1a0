// A value or the message that says why there is none: how the host Modbus
// library reports errors, so that nothing is thrown across its interface.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace hostmodbus {

template <typename T>
class Result {
public:
    static Result success(T value)
    {
        Result r;
        r.value_ = std::move(value);
        return r;
    }

    static Result failure(std::string message)
    {
        Result r;
        r.error_ = std::move(message);
        return r;
    }

    bool ok() const { return value_.has_value(); }
    const T& value() const { return *value_; }
    T& value() { return *value_; }
    /// Why there is no value; empty when there is one.
    const std::string& error() const { return error_; }

private:
    Result() = default;

    std::optional<T> value_;
    std::string error_;
};

} // namespace hostmodbus
