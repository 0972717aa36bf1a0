// A value or the SeiStatus that explains why there is none: the
// configuration protocol's counterpart of dcos::Result<T> and
// can::LinkResult<T>, with the same shape.
#pragma once

#include <sei/SeiStatus.hpp>

namespace sei {

template <typename T>
class SeiResult {
public:
    constexpr SeiResult(T value) : value_(value), status_(SeiStatus::Ok) {}
    constexpr SeiResult(SeiStatus status) : value_(), status_(status) {}

    constexpr bool ok() const { return status_ == SeiStatus::Ok; }
    constexpr SeiStatus status() const { return status_; }
    /// The value; only meaningful when ok() is true.
    constexpr const T& value() const { return value_; }

private:
    T value_;
    SeiStatus status_;
};

} // namespace sei
