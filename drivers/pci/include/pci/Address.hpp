// Where one PCI function sits: its bus, device and function numbers, the
// three fields of a configuration address (PCI Local Bus Specification 3.0,
// 3.2.2.3.2).
#pragma once

#include <pci/PciRegisters.hpp>

#include <stdint.h>

namespace pci {

struct Address {
    uint8_t bus = 0;
    uint8_t device = 0;   ///< 0-31.
    uint8_t function = 0; ///< 0-7.

    /// Whether the numbers fit the configuration address's fields; every
    /// bus number does.
    constexpr bool valid() const { return device < reg::kDevicesPerBus && function < reg::kFunctionsPerDevice; }

    constexpr bool operator==(const Address&) const = default;
};

} // namespace pci
