// What the enumeration reads of one PCI function: its address, identity,
// class, header layout and interrupt wiring (PCI Local Bus Specification
// 3.0, 6.2.1 and 6.2.4).
#pragma once

#include <pci/Address.hpp>
#include <pci/PciRegisters.hpp>

#include <stdint.h>

namespace pci {

struct Device {
    Address address{};
    uint16_t vendorId = reg::kVendorNone;
    uint16_t deviceId = 0xFFFF;
    uint8_t revision = 0;
    /// Base class in bits 23-16, sub-class in bits 15-8, programming
    /// interface in bits 7-0 (LB 6.2.1).
    uint32_t classCode = 0;
    /// The header's layout (reg::kHeaderTypeDevice, ...), without the
    /// multi-function bit.
    uint8_t headerType = reg::kHeaderTypeDevice;
    /// The multi-function bit of this function's Header Type; meaningful
    /// in function 0, which says whether functions 1-7 may exist.
    bool multiFunction = false;
    /// The subsystem's identity (LB 6.2.4); 0 outside a type 0 header.
    uint16_t subsystemVendorId = 0;
    uint16_t subsystemId = 0;
    /// The interrupt controller input the BIOS routed the pin to: an IRQ
    /// below 16, or reg::kInterruptLineUnknown (LB 6.2.4).
    uint8_t interruptLine = reg::kInterruptLineUnknown;
    /// reg::kInterruptPinNone, or 1-4 for INTA#-INTD# (LB 6.2.4).
    uint8_t interruptPin = reg::kInterruptPinNone;

    constexpr uint8_t baseClass() const { return static_cast<uint8_t>(classCode >> 16); }
    constexpr uint8_t subClass() const { return static_cast<uint8_t>(classCode >> 8); }
    constexpr uint8_t programmingInterface() const { return static_cast<uint8_t>(classCode); }

    /// How many Base Address Registers the header has: six in a device's
    /// header, two in a bridge's, none known in any other.
    constexpr unsigned barCount() const
    {
        return headerType == reg::kHeaderTypeDevice   ? reg::kDeviceBarCount
               : headerType == reg::kHeaderTypeBridge ? reg::kBridgeBarCount
                                                      : 0;
    }
};

} // namespace pci
