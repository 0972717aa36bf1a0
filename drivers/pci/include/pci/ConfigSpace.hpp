// PCI configuration space through configuration mechanism #1 (PCI Local
// Bus Specification 3.0, 3.2.2.3.2): the host bridge's CONFIG_ADDRESS
// register at port 0xCF8 selects a function's doubleword register, and
// CONFIG_DATA at 0xCFC reads or writes it, a byte or a word of it at
// 0xCFC + (offset & 3). Every PC since the PCI bus came has it, QEMU's pc
// machine (an i440FX) among them; the older mechanism #2, which later
// revisions of the specification no longer describe, is not supported.
//
// An access is two port operations, the address and then the data, and
// another access between them would take the address away: each is made
// with interrupts disabled on this processor, so an interrupt service
// routine may use ConfigSpace too. That does not order two processors: on
// the dual-Pentium board configuration space is used while the board
// brings its devices up, before the second processor runs, and whatever
// touches it later from two processors must hold one lock around it.
//
// Offsets are checked, never masked: a width the offset is not aligned to
// (a word at an odd offset, a doubleword not at a multiple of four) or an
// offset past the 256 bytes mechanism #1 reaches is refused with
// InvalidArgument and touches no port, as is a device above 31 or a
// function above 7. Errors are values; nothing here panics.
#pragma once

#include <pci/Address.hpp>
#include <pci/PciRegisters.hpp>

#include <arch_x86/IoWindow.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace pci {

class ConfigSpace {
public:
    /// The host bridge's configuration ports; nothing is touched until used.
    constexpr ConfigSpace()
        : window_(arch_x86::IoWindow::ports(reg::kConfigAddressPort, reg::kConfigPortCount))
    {
    }

    /// Whether mechanism #1 is there: CONFIG_ADDRESS must keep the enable
    /// bit written to it, as Linux's pci_check_type1 tests it. The register's
    /// old value is written back either way. NotFound where nothing holds
    /// the value (a machine without PCI reads all ones).
    dcos::Status probe() const;

    /// The configuration address that selects @p offset's doubleword of
    /// @p address (CONFIG_ADDRESS, LB 3.2.2.3.2).
    static constexpr uint32_t configAddress(Address address, unsigned offset)
    {
        return reg::kConfigAddressEnable | static_cast<uint32_t>(address.bus) << reg::kConfigAddressBusShift |
               static_cast<uint32_t>(address.device) << reg::kConfigAddressDeviceShift |
               static_cast<uint32_t>(address.function) << reg::kConfigAddressFunctionShift |
               (offset & reg::kConfigAddressRegisterMask);
    }

    /// Whether an access of @p width bytes (1, 2 or 4) at @p offset of
    /// @p address is one mechanism #1 can make.
    static constexpr bool accessible(Address address, unsigned offset, unsigned width)
    {
        return address.valid() && (width == 1 || width == 2 || width == 4) && (offset & (width - 1)) == 0 &&
               offset + width <= reg::kConfigSpaceSize;
    }

    /// The byte at @p offset; InvalidArgument for a bad address or offset.
    dcos::Result<uint8_t> read8(Address address, unsigned offset) const;
    /// The word at @p offset (even); InvalidArgument for a bad address or offset.
    dcos::Result<uint16_t> read16(Address address, unsigned offset) const;
    /// The doubleword at @p offset (a multiple of 4); InvalidArgument for a bad address or offset.
    dcos::Result<uint32_t> read32(Address address, unsigned offset) const;

    /// Writes the byte at @p offset; InvalidArgument for a bad address or offset.
    dcos::Status write8(Address address, unsigned offset, uint8_t value) const;
    /// Writes the word at @p offset (even); InvalidArgument for a bad address or offset.
    dcos::Status write16(Address address, unsigned offset, uint16_t value) const;
    /// Writes the doubleword at @p offset (a multiple of 4); InvalidArgument for a bad address or offset.
    dcos::Status write32(Address address, unsigned offset, uint32_t value) const;

    /// Read-modify-write of the command register (LB 6.2.2): sets @p set,
    /// then clears @p clear. Enabling a function's decode is
    /// updateCommand(address, reg::kCommandIoSpace, 0). InvalidArgument for
    /// a bad address.
    dcos::Status updateCommand(Address address, uint16_t set, uint16_t clear) const;

private:
    // One access: the address, then the data port at the offset's byte lane.
    uint32_t read(Address address, unsigned offset, unsigned width) const;
    void write(Address address, unsigned offset, unsigned width, uint32_t value) const;

    arch_x86::IoWindow window_;
};

} // namespace pci
