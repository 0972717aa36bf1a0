#include <pci/ConfigSpace.hpp>

#include <arch_x86/Cpu.hpp>

namespace pci {

using dcos::Result;
using dcos::Status;

Status ConfigSpace::probe() const
{
    // A machine without mechanism #1 has nothing at 0xCF8 (reads of all
    // ones), or a register that does not keep bit 31; either way the value
    // written does not come back. Linux's probe first writes 0x01 to port
    // 0xCFB as well, for a few early chipsets; this one leaves that port
    // alone, as the chipsets DCOS runs on (QEMU's i440FX among them) need
    // nothing there.
    const arch_x86::InterruptGuard guard;
    const uint32_t saved = window_.read32(0);
    window_.write32(0, reg::kConfigAddressEnable);
    const uint32_t echoed = window_.read32(0);
    window_.write32(0, saved);
    return echoed == reg::kConfigAddressEnable ? Status::Ok : Status::NotFound;
}

uint32_t ConfigSpace::read(Address address, unsigned offset, unsigned width) const
{
    const arch_x86::InterruptGuard guard;
    window_.write32(0, configAddress(address, offset));
    // The byte lanes of CONFIG_DATA are the register's bytes (LB 3.2.2.3.2).
    const unsigned lane = reg::kConfigDataOffset + (offset & 3u);
    if (width == 1) {
        return window_.read8(lane);
    }
    if (width == 2) {
        return window_.read16(lane);
    }
    return window_.read32(lane);
}

void ConfigSpace::write(Address address, unsigned offset, unsigned width, uint32_t value) const
{
    const arch_x86::InterruptGuard guard;
    window_.write32(0, configAddress(address, offset));
    const unsigned lane = reg::kConfigDataOffset + (offset & 3u);
    if (width == 1) {
        window_.write8(lane, static_cast<uint8_t>(value));
    } else if (width == 2) {
        window_.write16(lane, static_cast<uint16_t>(value));
    } else {
        window_.write32(lane, value);
    }
}

Result<uint8_t> ConfigSpace::read8(Address address, unsigned offset) const
{
    if (!accessible(address, offset, 1)) {
        return Status::InvalidArgument;
    }
    return static_cast<uint8_t>(read(address, offset, 1));
}

Result<uint16_t> ConfigSpace::read16(Address address, unsigned offset) const
{
    if (!accessible(address, offset, 2)) {
        return Status::InvalidArgument;
    }
    return static_cast<uint16_t>(read(address, offset, 2));
}

Result<uint32_t> ConfigSpace::read32(Address address, unsigned offset) const
{
    if (!accessible(address, offset, 4)) {
        return Status::InvalidArgument;
    }
    return read(address, offset, 4);
}

Status ConfigSpace::write8(Address address, unsigned offset, uint8_t value) const
{
    if (!accessible(address, offset, 1)) {
        return Status::InvalidArgument;
    }
    write(address, offset, 1, value);
    return Status::Ok;
}

Status ConfigSpace::write16(Address address, unsigned offset, uint16_t value) const
{
    if (!accessible(address, offset, 2)) {
        return Status::InvalidArgument;
    }
    write(address, offset, 2, value);
    return Status::Ok;
}

Status ConfigSpace::write32(Address address, unsigned offset, uint32_t value) const
{
    if (!accessible(address, offset, 4)) {
        return Status::InvalidArgument;
    }
    write(address, offset, 4, value);
    return Status::Ok;
}

Status ConfigSpace::updateCommand(Address address, uint16_t set, uint16_t clear) const
{
    const Result<uint16_t> command = read16(address, reg::kCommand);
    if (!command.ok()) {
        return command.status();
    }
    // The command register is read-write as a whole (LB 6.2.2): writing back
    // the bits read keeps every setting but the ones changed here. The
    // status register beside it has write-one-to-clear bits, which is why
    // this is a word access and never a doubleword one.
    const uint16_t updated = static_cast<uint16_t>((command.value() | set) & ~clear);
    return write16(address, reg::kCommand, updated);
}

} // namespace pci
