// Ports, configuration registers and bits of conventional PCI, as the
// firmware reaches them through configuration mechanism #1.
//
// Every constant cites the section of the PCI Local Bus Specification,
// revision 3.0 (PCI-SIG, 2004) that defines it; "LB 6.2.5.1" means its
// section 6.2.5.1. No other file of the driver spells a configuration
// register offset or a bit as a bare number.
#pragma once

#include <stdint.h>

namespace pci::reg {

// -- Configuration mechanism #1 (LB 3.2.2.3.2) --------------------------------

/// CONFIG_ADDRESS: a 32-bit register that selects the bus, device,
/// function and register the next CONFIG_DATA access reaches.
constexpr uint16_t kConfigAddressPort = 0xCF8;
/// CONFIG_DATA: the selected register's doubleword; a byte or word access
/// at kConfigDataPort + (offset & 3) reaches that part of it.
constexpr uint16_t kConfigDataPort = 0xCFC;
/// The ports both registers take together, 0xCF8 to 0xCFF.
constexpr uint16_t kConfigPortCount = 8;
/// CONFIG_DATA's place among those ports.
constexpr uint16_t kConfigDataOffset = kConfigDataPort - kConfigAddressPort;

/// CONFIG_ADDRESS bit 31: the enable bit. Only with it set does an access
/// to CONFIG_DATA become a configuration transaction.
constexpr uint32_t kConfigAddressEnable = 1u << 31;
constexpr unsigned kConfigAddressBusShift = 16;      ///< Bits 23-16: bus number.
constexpr unsigned kConfigAddressDeviceShift = 11;   ///< Bits 15-11: device number.
constexpr unsigned kConfigAddressFunctionShift = 8;  ///< Bits 10-8: function number.
/// Bits 7-2: the doubleword register; bits 1-0 are 0 (a type 0 access).
constexpr uint32_t kConfigAddressRegisterMask = 0xFC;

constexpr unsigned kBusCount = 256;            ///< Eight bits of bus number.
constexpr unsigned kDevicesPerBus = 32;        ///< Five bits of device number.
constexpr unsigned kFunctionsPerDevice = 8;    ///< Three bits of function number.
/// Bytes of one function's configuration space (LB 6.1); mechanism #1
/// reaches no further.
constexpr unsigned kConfigSpaceSize = 256;

// -- The predefined header (LB 6.1, figure 6-1) -----------------------------
// The first 16 bytes are common to every header type; what follows them
// here is the type 0 (device) layout.

constexpr uint8_t kVendorId = 0x00;        ///< Vendor ID (LB 6.2.1).
constexpr uint8_t kDeviceId = 0x02;        ///< Device ID (LB 6.2.1).
constexpr uint8_t kCommand = 0x04;         ///< Command register (LB 6.2.2).
constexpr uint8_t kStatus = 0x06;          ///< Status register (LB 6.2.3).
/// The doubleword of the Revision ID (byte 0x08) and the Class Code
/// (bytes 0x09-0x0B: programming interface, sub-class, base class) (LB 6.2.1).
constexpr uint8_t kRevisionAndClass = 0x08;
constexpr unsigned kClassCodeShift = 8;    ///< The class code's place in that doubleword.
constexpr uint8_t kHeaderType = 0x0E;      ///< Header Type (LB 6.2.1).
constexpr uint8_t kBar0 = 0x10;            ///< Base Address Register 0; BAR n is at kBar0 + 4 n (LB 6.2.5).
constexpr uint8_t kBarSize = 4;            ///< Bytes per Base Address Register.
constexpr uint8_t kSubsystemVendorId = 0x2C; ///< Subsystem Vendor ID, type 0 only (LB 6.2.4).
constexpr uint8_t kSubsystemId = 0x2E;     ///< Subsystem ID, type 0 only (LB 6.2.4).
constexpr uint8_t kInterruptLine = 0x3C;   ///< Interrupt Line (LB 6.2.4).
constexpr uint8_t kInterruptPin = 0x3D;    ///< Interrupt Pin (LB 6.2.4).

/// The Vendor ID a read returns where no function answers: the host bridge
/// ends the master-aborted read with all ones, and 0FFFFh is no vendor's
/// (LB 6.1, 6.2.1).
constexpr uint16_t kVendorNone = 0xFFFF;

// Command register bits (LB 6.2.2).
constexpr uint16_t kCommandIoSpace = 1u << 0;      ///< The function answers its I/O BARs.
constexpr uint16_t kCommandMemorySpace = 1u << 1;  ///< The function answers its memory BARs.
constexpr uint16_t kCommandBusMaster = 1u << 2;    ///< The function may start transactions (DMA).
/// Set: the function may not assert its INTx# pin.
constexpr uint16_t kCommandInterruptDisable = 1u << 10;
/// The decode enables that sizing a BAR clears meanwhile (LB 6.2.5.1).
constexpr uint16_t kCommandDecode = kCommandIoSpace | kCommandMemorySpace;

// Status register bits (LB 6.2.3).
constexpr uint16_t kStatusInterrupt = 1u << 3;     ///< The function's INTx# is asserted (or would be).
constexpr uint16_t kStatusCapabilities = 1u << 4;  ///< A capabilities list starts at 0x34.

// Header Type (LB 6.2.1).
constexpr uint8_t kHeaderTypeMultiFunction = 1u << 7; ///< Bit 7 of function 0: functions 1-7 may exist.
constexpr uint8_t kHeaderTypeLayoutMask = 0x7F;       ///< Bits 6-0: the layout from 0x10 on.
constexpr uint8_t kHeaderTypeDevice = 0x00;           ///< Type 0: a device, six BARs (LB 6.1).
/// Type 1: a PCI-to-PCI bridge, two BARs (PCI-to-PCI Bridge Architecture Specification 1.2, chapter 3).
constexpr uint8_t kHeaderTypeBridge = 0x01;
constexpr uint8_t kHeaderTypeCardBus = 0x02;          ///< Type 2: a CardBus bridge (PC Card Standard).
constexpr unsigned kDeviceBarCount = 6;               ///< BARs of a type 0 header (LB 6.2.5).
constexpr unsigned kBridgeBarCount = 2;               ///< BARs of a type 1 header (bridge specification, chapter 3).

// Interrupt Line and Pin (LB 6.2.4).
/// On x86 PCs the line holds the 8259 input (IRQ 0-15) the firmware routed
/// INTx# to; 255 means unknown or not connected, and 16-254 are reserved.
constexpr uint8_t kInterruptLineUnknown = 0xFF;
constexpr uint8_t kInterruptLineLimit = 16;           ///< Lines below it are IRQ numbers.
constexpr uint8_t kInterruptPinNone = 0;              ///< The function uses no interrupt pin.
constexpr uint8_t kInterruptPinA = 1;                 ///< INTA#; 2-4 are INTB#-INTD#.
constexpr uint8_t kInterruptPinD = 4;

// Base Address Registers (LB 6.2.5.1).
constexpr uint32_t kBarSpaceIo = 1u << 0;             ///< Bit 0 set: an I/O BAR; clear: a memory BAR.
constexpr uint32_t kBarIoAddressMask = 0xFFFFFFFC;    ///< I/O BAR: bits 31-2 are the address.
constexpr uint32_t kBarMemoryTypeMask = 0x6;          ///< Memory BAR bits 2-1: where it may be placed.
constexpr uint32_t kBarMemoryType32 = 0x0;            ///< 00: anywhere in 32-bit space.
constexpr uint32_t kBarMemoryTypeBelow1M = 0x2;       ///< 01: below 1 MiB (reserved since revision 2.2).
constexpr uint32_t kBarMemoryType64 = 0x4;            ///< 10: anywhere in 64-bit space; the next BAR holds bits 63-32.
constexpr uint32_t kBarMemoryPrefetchable = 1u << 3;  ///< Bit 3: reads have no side effects.
constexpr uint32_t kBarMemoryAddressMask = 0xFFFFFFF0; ///< Memory BAR: bits 31-4 are the address.
/// What sizing writes: the BAR then reads back zeros in the bits its size
/// fixes and the read-only type bits (LB 6.2.5.1).
constexpr uint32_t kBarSizingPattern = 0xFFFFFFFF;

} // namespace pci::reg
