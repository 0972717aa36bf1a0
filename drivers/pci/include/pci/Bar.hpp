// One Base Address Register of a PCI function: what kind of space it asks
// for, where the BIOS put it and how large it is (PCI Local Bus
// Specification 3.0, 6.2.5.1).
//
// The low bits say the kind: bit 0 set is I/O space with the address in
// bits 31-2; clear is memory, with the type in bits 2-1 (32-bit, or 64-bit
// with the upper half in the next register) and bit 3 set when it is
// prefetchable. The size is not stored anywhere: the address bits below it
// are hardwired to zero, so writing all ones and reading back shows them.
// Sizing turns the function's decode off meanwhile (LB 6.2.5.1 asks it, as
// the BAR points at an all-ones address in between), and puts the BAR and
// the command register back as it found them.
//
// The firmware is 32-bit: a 64-bit BAR the BIOS placed above 4 GiB, or
// one 4 GiB or larger, cannot be reached and is refused with NotSupported.
#pragma once

#include <pci/ConfigSpace.hpp>
#include <pci/Device.hpp>

#include <dcos/Status.hpp>

#include <stdint.h>

namespace pci {

struct Bar {
    enum class Kind : uint8_t {
        None,     ///< The register is not implemented (it reads back zero).
        Io,       ///< I/O space.
        Memory32, ///< Memory anywhere below 4 GiB (or, type 01, below 1 MiB).
        Memory64, ///< Memory anywhere in 64-bit space; takes two registers.
    };

    Kind kind = Kind::None;
    uint32_t base = 0;         ///< The address the BIOS assigned (0: none).
    uint32_t size = 0;         ///< Bytes the function decodes, a power of two.
    bool prefetchable = false; ///< Memory only: reads have no side effects.
    /// Base Address Registers it takes: 2 for a 64-bit BAR, else 1; the
    /// next BAR of the function is at index + registers.
    uint8_t registers = 1;

    /// Decodes and sizes BAR @p index of @p device. InvalidArgument for an
    /// index the header has no BAR at; NotSupported for a reserved memory
    /// type, a 64-bit BAR in the last register, and a 64-bit BAR above
    /// 4 GiB or of 4 GiB or more. @p index must not be the upper half of a
    /// 64-bit BAR (Bar::registers says where the next BAR is).
    static dcos::Result<Bar> probe(const ConfigSpace& config, const Device& device, unsigned index);
};

} // namespace pci
