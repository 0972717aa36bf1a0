// A register-level stand-in for a host bridge's PCI configuration
// mechanism #1, answering the recording port mock at 0xCF8-0xCFF with the
// configuration space of the functions a test adds. It serves the PCI
// tests and the tests of drivers that find their card on the bus, so both
// run against the same model of the hardware.
//
// It follows the specification where the drivers depend on it:
// CONFIG_ADDRESS reads back what was written, CONFIG_DATA answers only with
// the enable bit set, an absent function reads all ones, a BAR keeps only
// its writable address bits (so all ones read back give its size) and its
// read-only type bits, the command register keeps its writable bits, and
// the interrupt line takes what is written to it. BARs must be written
// whole, as Bar::probe writes them, so a narrower write fails the test.
#pragma once

#include <pci/Address.hpp>
#include <pci/PciRegisters.hpp>

#include "../../../firmware/arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <vector>

namespace pci_test {

class FakeConfigSpace final : public port_io_mock::Responder {
public:
    /// The revision every added function reports, so that a test can check
    /// the revision is taken from the low byte of the class code doubleword.
    static constexpr uint8_t kRevision = 0x02;

    /// One function's 256 bytes of configuration space, with what a test
    /// needs to model its BARs and to see how the driver sized them.
    struct Function {
        uint8_t bytes[pci::reg::kConfigSpaceSize] = {};
        /// The bits of each BAR a write may change; 0 for a BAR the function
        /// does not implement, which therefore reads back 0 after sizing.
        uint32_t barWritable[pci::reg::kDeviceBarCount] = {};
        /// The command register when all ones were last written to a BAR,
        /// so a test can check decode was off while the BAR was sized.
        uint16_t commandWhenSized = 0xFFFF;
        /// How many times all ones were written to one of the BARs.
        unsigned sizings = 0;

        uint32_t read(unsigned offset, unsigned width) const
        {
            uint32_t value = 0;
            for (unsigned i = 0; i < width; ++i) {
                value |= static_cast<uint32_t>(bytes[offset + i]) << (8 * i);
            }
            return value;
        }

        /// Sets @p width bytes from @p offset as the test wants them, with
        /// none of the write masks the bus applies.
        void store(unsigned offset, unsigned width, uint32_t value)
        {
            for (unsigned i = 0; i < width; ++i) {
                bytes[offset + i] = static_cast<uint8_t>(value >> (8 * i));
            }
        }

        uint16_t command() const { return static_cast<uint16_t>(read(pci::reg::kCommand, 2)); }
        uint32_t bar(unsigned index) const { return read(pci::reg::kBar0 + 4 * index, 4); }

        /// Makes BAR @p index an I/O BAR of @p size ports placed at @p base.
        /// @p decoded limits the address bits the function implements, as a
        /// device that hardwires the upper half of its I/O BAR to zero does.
        void ioBar(unsigned index, uint32_t base, uint32_t size, uint32_t decoded = 0xFFFFFFFF)
        {
            barWritable[index] = ~(size - 1) & pci::reg::kBarIoAddressMask & decoded;
            store(pci::reg::kBar0 + 4 * index, 4, base | pci::reg::kBarSpaceIo);
        }

        /// Makes BAR @p index a 32-bit memory BAR of @p size bytes at @p base.
        void memoryBar(unsigned index, uint32_t base, uint32_t size, bool prefetchable = false)
        {
            barWritable[index] = ~(size - 1) & pci::reg::kBarMemoryAddressMask;
            store(pci::reg::kBar0 + 4 * index, 4, base | (prefetchable ? pci::reg::kBarMemoryPrefetchable : 0));
        }

        /// Makes BARs @p index and @p index + 1 a 64-bit memory BAR of
        /// @p size bytes at @p base. In the last BAR there is no register
        /// for the upper half, so only the lower half is set, letting a test
        /// check that the driver refuses such a BAR.
        void memory64Bar(unsigned index, uint64_t base, uint64_t size, bool prefetchable = false)
        {
            const uint64_t writable = ~(size - 1);
            barWritable[index] = static_cast<uint32_t>(writable) & pci::reg::kBarMemoryAddressMask;
            store(pci::reg::kBar0 + 4 * index, 4,
                  static_cast<uint32_t>(base) | pci::reg::kBarMemoryType64 |
                      (prefetchable ? pci::reg::kBarMemoryPrefetchable : 0));
            if (index + 1 < pci::reg::kDeviceBarCount) {
                barWritable[index + 1] = static_cast<uint32_t>(writable >> 32);
                store(pci::reg::kBar0 + 4 * (index + 1), 4, static_cast<uint32_t>(base >> 32));
            }
        }
    };

    /// Answers the configuration ports until port_io_mock::reset().
    FakeConfigSpace() { port_io_mock::attach(pci::reg::kConfigAddressPort, pci::reg::kConfigPortCount, this); }

    /// Adds a function with its identity and class, revision kRevision, no
    /// BARs and no interrupt routed, as a test then fills it in.
    Function& add(pci::Address address, uint16_t vendor, uint16_t device, uint32_t classCode,
                  uint8_t headerType = pci::reg::kHeaderTypeDevice)
    {
        Function& f = functions[key(address)];
        f.store(pci::reg::kVendorId, 2, vendor);
        f.store(pci::reg::kDeviceId, 2, device);
        f.store(pci::reg::kRevisionAndClass, 4, classCode << pci::reg::kClassCodeShift | kRevision);
        f.store(pci::reg::kHeaderType, 1, headerType);
        f.store(pci::reg::kInterruptLine, 1, pci::reg::kInterruptLineUnknown);
        return f;
    }

    /// A function added before; it must exist.
    Function& at(pci::Address address) { return functions.at(key(address)); }

    uint32_t read(uint16_t offset, int width) override
    {
        if (offset < pci::reg::kConfigDataOffset) {
            return offset == 0 && width == 32 ? configAddress : 0xFFFFFFFF;
        }
        const unsigned bytes = static_cast<unsigned>(width) / 8;
        const Function* f = selected();
        if (f == nullptr) {
            return bytes == 4 ? 0xFFFFFFFF : (1u << (8 * bytes)) - 1;
        }
        return f->read(registerOffset(offset), bytes);
    }

    void write(uint16_t offset, uint32_t value, int width) override
    {
        if (offset < pci::reg::kConfigDataOffset) {
            if (offset == 0 && width == 32) {
                configAddress = value;
            }
            return;
        }
        Function* f = selected();
        if (f == nullptr) {
            return;
        }
        const unsigned at = registerOffset(offset);
        const unsigned bytes = static_cast<unsigned>(width) / 8;
        if (at >= pci::reg::kBar0 && at < pci::reg::kBar0 + 4 * pci::reg::kDeviceBarCount) {
            ASSERT_EQ(bytes, 4u) << "BARs are written whole";
            const unsigned index = (at - pci::reg::kBar0) / 4;
            if (value == pci::reg::kBarSizingPattern) {
                f->commandWhenSized = f->command();
                ++f->sizings;
            }
            const uint32_t writable = f->barWritable[index];
            f->store(at, 4, (value & writable) | (f->bar(index) & ~writable));
        } else if (at == pci::reg::kCommand && bytes == 2) {
            const uint16_t writable =
                pci::reg::kCommandDecode | pci::reg::kCommandBusMaster | pci::reg::kCommandInterruptDisable;
            f->store(at, 2, (value & writable) | (f->command() & ~writable));
        } else if (at == pci::reg::kInterruptLine && bytes == 1) {
            f->store(at, 1, value);
        }
    }

    /// CONFIG_ADDRESS as last written; a test may set it to check that the
    /// driver puts back what it found.
    uint32_t configAddress = 0;
    /// Functions that answer every function number of their device, as a
    /// single-function device that ignores the function number does.
    std::vector<pci::Address> aliased;

private:
    static uint32_t key(pci::Address a) { return uint32_t{a.bus} << 16 | uint32_t{a.device} << 8 | a.function; }

    unsigned registerOffset(uint16_t dataOffset) const
    {
        return (configAddress & pci::reg::kConfigAddressRegisterMask) + (dataOffset - pci::reg::kConfigDataOffset);
    }

    // The function CONFIG_ADDRESS selects, or none while its enable bit is
    // clear or nothing is there.
    Function* selected()
    {
        if ((configAddress & pci::reg::kConfigAddressEnable) == 0) {
            return nullptr;
        }
        pci::Address a{static_cast<uint8_t>(configAddress >> pci::reg::kConfigAddressBusShift),
                       static_cast<uint8_t>((configAddress >> pci::reg::kConfigAddressDeviceShift) & 0x1F),
                       static_cast<uint8_t>((configAddress >> pci::reg::kConfigAddressFunctionShift) & 0x7)};
        for (const pci::Address& alias : aliased) {
            if (alias.bus == a.bus && alias.device == a.device) {
                a.function = 0;
            }
        }
        const auto found = functions.find(key(a));
        return found == functions.end() ? nullptr : &found->second;
    }

    std::map<uint32_t, Function> functions;
};

} // namespace pci_test
