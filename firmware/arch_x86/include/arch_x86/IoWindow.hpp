// One checked window onto a device's registers, in port or memory space.
//
// A driver is written once against IoWindow and works whether its chip sits
// behind ISA ports or a PCI memory BAR: the bus front end decides which kind
// of window it hands to the chip core. Every access is bounds-checked
// against the window's size, so a wrong register offset stops the node with
// a clear panic instead of silently poking another device.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <arch_x86/PortIo.hpp>

extern "C" [[noreturn]] void dcosPanic(const char* format, ...);

namespace arch_x86 {

class IoWindow {
public:
    enum class Space : uint8_t { Port, Memory };

    /// A window of size bytes of I/O ports starting at base.
    static constexpr IoWindow ports(uint16_t base, uint16_t size) { return {Space::Port, base, size}; }

    /// A window of size bytes of memory-mapped registers starting at base.
    static constexpr IoWindow memory(uintptr_t base, size_t size) { return {Space::Memory, base, size}; }

    constexpr IoWindow() = default;

    uint8_t read8(size_t offset) const
    {
        check(offset, 1);
        if (space_ == Space::Port) {
            return portRead8(static_cast<uint16_t>(base_ + offset));
        }
        return *reinterpret_cast<volatile uint8_t*>(base_ + offset);
    }

    uint16_t read16(size_t offset) const
    {
        check(offset, 2);
        if (space_ == Space::Port) {
            return portRead16(static_cast<uint16_t>(base_ + offset));
        }
        return *reinterpret_cast<volatile uint16_t*>(base_ + offset);
    }

    void write8(size_t offset, uint8_t value) const
    {
        check(offset, 1);
        if (space_ == Space::Port) {
            portWrite8(static_cast<uint16_t>(base_ + offset), value);
        } else {
            *reinterpret_cast<volatile uint8_t*>(base_ + offset) = value;
        }
    }

    void write16(size_t offset, uint16_t value) const
    {
        check(offset, 2);
        if (space_ == Space::Port) {
            portWrite16(static_cast<uint16_t>(base_ + offset), value);
        } else {
            *reinterpret_cast<volatile uint16_t*>(base_ + offset) = value;
        }
    }

    uint32_t read32(size_t offset) const
    {
        check(offset, 4);
        if (space_ == Space::Port) {
            return portRead32(static_cast<uint16_t>(base_ + offset));
        }
        return *reinterpret_cast<volatile uint32_t*>(base_ + offset);
    }

    void write32(size_t offset, uint32_t value) const
    {
        check(offset, 4);
        if (space_ == Space::Port) {
            portWrite32(static_cast<uint16_t>(base_ + offset), value);
        } else {
            *reinterpret_cast<volatile uint32_t*>(base_ + offset) = value;
        }
    }

    Space space() const { return space_; }
    uintptr_t base() const { return base_; }
    size_t size() const { return size_; }

private:
    constexpr IoWindow(Space space, uintptr_t base, size_t size) : space_(space), base_(base), size_(size) {}

    void check(size_t offset, size_t width) const
    {
        if (offset + width > size_ || (offset & (width - 1)) != 0) {
            dcosPanic("I/O window %s 0x%lx+%lu: bad %lu-byte access at offset 0x%lx",
                      space_ == Space::Port ? "port" : "memory", static_cast<unsigned long>(base_),
                      static_cast<unsigned long>(size_), static_cast<unsigned long>(width),
                      static_cast<unsigned long>(offset));
        }
    }

    Space space_ = Space::Port;
    uintptr_t base_ = 0;
    size_t size_ = 0;
};

} // namespace arch_x86
