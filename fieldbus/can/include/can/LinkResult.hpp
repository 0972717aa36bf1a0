// A value or the LinkError that explains why there is none.
//
// The link layer's counterpart of dcos::Result<T>: the same shape, so code
// moving between the two reads the same, but carrying the link layer's own
// reasons. It is constexpr, so identifiers can be encoded and checked by the
// compiler (MessageIdentifier's static_asserts) with the code the node runs.
#pragma once

#include <can/LinkError.hpp>

namespace can {

template <typename T>
class LinkResult {
public:
    constexpr LinkResult(T value) : value_(value), error_(LinkError::Ok) {}
    constexpr LinkResult(LinkError error) : value_(), error_(error) {}

    constexpr bool ok() const { return error_ == LinkError::Ok; }
    constexpr LinkError error() const { return error_; }
    /// The value; only meaningful when ok() is true.
    constexpr const T& value() const { return value_; }

private:
    T value_;
    LinkError error_;
};

} // namespace can
