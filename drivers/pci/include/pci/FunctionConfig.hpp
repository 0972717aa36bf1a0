// The configuration space of one function, for a sequence of accesses that
// is checked once at its end.
//
// A driver's configuration code is a run of register accesses, each of
// which ConfigSpace may refuse (a bad address or offset). Checking every
// one would bury the sequence; FunctionConfig keeps the first refusal and
// lets the rest of the sequence run harmlessly: a refused read gives all
// ones, what an absent function reads as (LB 6.1), and a write after a
// refusal is not made. status() then says whether everything went through.
#pragma once

#include <pci/Address.hpp>
#include <pci/ConfigSpace.hpp>

#include <dcos/Status.hpp>

#include <stdint.h>

namespace pci {

class FunctionConfig {
public:
    /// The function at @p address of @p config.
    constexpr FunctionConfig(const ConfigSpace& config, Address address) : config_(config), address_(address) {}

    /// The byte at @p offset, or 0xFF once an access was refused.
    uint8_t read8(unsigned offset)
    {
        return status_ == dcos::Status::Ok ? take(config_.read8(address_, offset), uint8_t{0xFF}) : uint8_t{0xFF};
    }
    /// The word at @p offset, or 0xFFFF once an access was refused.
    uint16_t read16(unsigned offset)
    {
        return status_ == dcos::Status::Ok ? take(config_.read16(address_, offset), uint16_t{0xFFFF})
                                           : uint16_t{0xFFFF};
    }
    /// The doubleword at @p offset, or all ones once an access was refused.
    uint32_t read32(unsigned offset)
    {
        return status_ == dcos::Status::Ok ? take(config_.read32(address_, offset), uint32_t{0xFFFFFFFF})
                                           : uint32_t{0xFFFFFFFF};
    }

    /// Writes the byte at @p offset unless an access was refused.
    void write8(unsigned offset, uint8_t value)
    {
        if (status_ == dcos::Status::Ok) {
            status_ = config_.write8(address_, offset, value);
        }
    }
    /// Writes the word at @p offset unless an access was refused.
    void write16(unsigned offset, uint16_t value)
    {
        if (status_ == dcos::Status::Ok) {
            status_ = config_.write16(address_, offset, value);
        }
    }
    /// Writes the doubleword at @p offset unless an access was refused.
    void write32(unsigned offset, uint32_t value)
    {
        if (status_ == dcos::Status::Ok) {
            status_ = config_.write32(address_, offset, value);
        }
    }

    /// Ok when every access went through, else the first refusal.
    dcos::Status status() const { return status_; }
    Address address() const { return address_; }

private:
    // The value of a read made while nothing was refused, or @p refused
    // with the refusal kept.
    template <typename T>
    T take(const dcos::Result<T>& result, T refused)
    {
        if (!result.ok()) {
            status_ = result.status();
            return refused;
        }
        return result.value();
    }

    const ConfigSpace& config_;
    Address address_;
    dcos::Status status_ = dcos::Status::Ok;
};

} // namespace pci
