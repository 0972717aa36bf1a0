// PCI configuration mechanism #1, bus 0 enumeration and BAR decoding,
// against a register-level fake host bridge answering the recording port
// mock at 0xCF8-0xCFF: a machine laid out like QEMU's pc (an i440FX host
// bridge, the multi-function PIIX3, VGA) with a Kvaser PCIcan, a device
// with 64-bit BARs, a single-function device that answers every function
// number, a PCI-to-PCI bridge and a device in the last slot.
#include <pci/Bar.hpp>
#include <pci/ConfigSpace.hpp>
#include <pci/Enumerator.hpp>
#include <pci/FunctionConfig.hpp>

#include "../../../firmware/arch_x86/unit_tests/PortIoMock.hpp"
#include "FakeConfigSpace.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace {

using dcos::Result;
using dcos::Status;
using pci::Address;
using pci::Bar;
using pci::ConfigSpace;
using pci::Device;
using pci::Enumerator;
namespace reg = pci::reg;
using pci_test::FakeConfigSpace;

constexpr Address kHostBridge{0, 0, 0};
constexpr Address kIsaBridge{0, 1, 0};
constexpr Address kIde{0, 1, 1};
constexpr Address kAcpi{0, 1, 3};
constexpr Address kVga{0, 2, 0};
constexpr Address kNvme{0, 3, 0};
constexpr Address kKvaser{0, 4, 0};
constexpr Address kNic{0, 5, 0};
constexpr Address kPciBridge{0, 6, 0};
constexpr Address kVirtio0{0, 8, 0};
constexpr Address kVirtio1{0, 9, 0};
constexpr Address kLastSlot{0, 31, 0};

class PciTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        port_io_mock::reset();
        fake = std::make_unique<FakeConfigSpace>();
        fake->add(kHostBridge, 0x8086, 0x1237, 0x060000);
        fake->add(kIsaBridge, 0x8086, 0x7000, 0x060100, reg::kHeaderTypeMultiFunction);
        fake->add(kIde, 0x8086, 0x7010, 0x010180).ioBar(4, 0xC140, 16, 0x0000FFFF);
        FakeConfigSpace::Function& acpi = fake->add(kAcpi, 0x8086, 0x7113, 0x068000);
        acpi.store(reg::kInterruptLine, 1, 9);
        acpi.store(reg::kInterruptPin, 1, reg::kInterruptPinA);
        FakeConfigSpace::Function& vga = fake->add(kVga, 0x1234, 0x1111, 0x030000);
        vga.memoryBar(0, 0xFD000000, 16u << 20, true);
        vga.memoryBar(2, 0xFEBF0000, 4096, false);
        vga.store(reg::kCommand, 2, reg::kCommandIoSpace | reg::kCommandMemorySpace | reg::kCommandBusMaster);
        FakeConfigSpace::Function& nvme = fake->add(kNvme, 0x1B36, 0x0010, 0x010802);
        nvme.memory64Bar(0, 0xFEBF4000, 16 * 1024, false);
        nvme.memory64Bar(2, 0x800000000ull, 1u << 20, true);
        nvme.memory64Bar(5, 0xFEC00000, 4096, false); // Its upper half would be BAR6.
        nvme.store(reg::kCommand, 2, reg::kCommandMemorySpace);
        FakeConfigSpace::Function& kvaser = fake->add(kKvaser, 0x10E8, 0x8406, 0xFF0000);
        kvaser.ioBar(0, 0xC000, 0x80);
        kvaser.ioBar(1, 0xC080, 0x80);
        kvaser.ioBar(2, 0xC100, 0x08);
        kvaser.store(reg::kInterruptLine, 1, 11);
        kvaser.store(reg::kInterruptPin, 1, reg::kInterruptPinA);
        kvaser.store(reg::kSubsystemVendorId, 2, 0x10E8);
        kvaser.store(reg::kSubsystemId, 2, 0x8406);
        fake->add(kNic, 0x8086, 0x100E, 0x020000);
        fake->aliased.push_back(kNic);
        FakeConfigSpace::Function& bridge = fake->add(kPciBridge, 0x1B36, 0x0001, 0x060400, reg::kHeaderTypeBridge);
        bridge.store(reg::kSubsystemVendorId, 2, 0x1234); // A bridge's I/O window, not a subsystem.
        fake->add(kVirtio0, 0x1AF4, 0x1000, 0x020000);
        fake->add(kVirtio1, 0x1AF4, 0x1000, 0x020000);
        fake->add(kLastSlot, 0x8086, 0x2918, 0x060100);
        port_io_mock::takeLog();
    }

    Device device(Address address)
    {
        const Result<Device> read = Enumerator(config).read(address);
        EXPECT_TRUE(read.ok()) << dcos::statusName(read.status());
        return read.value();
    }

    std::unique_ptr<FakeConfigSpace> fake;
    ConfigSpace config;
};

// -- configuration mechanism #1 ----------------------------------------------

TEST_F(PciTest, ConfigAddressCarriesBusDeviceFunctionAndRegister)
{
    EXPECT_EQ(ConfigSpace::configAddress({1, 4, 2}, 0x3D), 0x8001223Cu) << "bits 1-0 of the offset are byte lanes";
    EXPECT_EQ(ConfigSpace::configAddress({0xFF, 31, 7}, 0xFC), 0x80FFFFFCu);
    EXPECT_EQ(ConfigSpace::configAddress({0, 0, 0}, 0), reg::kConfigAddressEnable);
}

TEST_F(PciTest, ProbeFindsTheMechanismAndRestoresTheAddressRegister)
{
    fake->configAddress = 0x80001234;
    EXPECT_EQ(config.probe(), Status::Ok);
    EXPECT_EQ(fake->configAddress, 0x80001234u);
    const auto log = port_io_mock::takeLog();
    const std::vector<port_io_mock::Access> expected = {
        {false, 0xCF8, 0x80001234, 32},
        {true, 0xCF8, 0x80000000, 32},
        {false, 0xCF8, 0x80000000, 32},
        {true, 0xCF8, 0x80001234, 32},
    };
    EXPECT_EQ(log, expected) << port_io_mock::describe(log);
}

TEST_F(PciTest, ProbeWithoutTheMechanismIsNotFound)
{
    port_io_mock::reset(); // No host bridge: the ports read all ones.
    port_io_mock::setDefaultRead(0xCF8, 0xFFFFFFFF);
    EXPECT_EQ(config.probe(), Status::NotFound);
    const auto log = port_io_mock::takeLog();
    ASSERT_EQ(log.size(), 4u) << port_io_mock::describe(log);
    EXPECT_EQ(log[3], (port_io_mock::Access{true, 0xCF8, 0xFFFFFFFF, 32})) << "what was read goes back";
}

TEST_F(PciTest, ByteAndWordAccessesUseTheDataPortsByteLanes)
{
    const Result<uint8_t> pin = config.read8(kKvaser, reg::kInterruptPin);
    ASSERT_TRUE(pin.ok());
    EXPECT_EQ(pin.value(), reg::kInterruptPinA);
    const Result<uint16_t> id = config.read16(kKvaser, reg::kDeviceId);
    ASSERT_TRUE(id.ok());
    EXPECT_EQ(id.value(), 0x8406);
    EXPECT_EQ(config.write8(kKvaser, reg::kInterruptLine, 5), Status::Ok);
    const Result<uint32_t> ids = config.read32(kKvaser, reg::kVendorId);
    ASSERT_TRUE(ids.ok());
    EXPECT_EQ(ids.value(), 0x840610E8u);
    const auto log = port_io_mock::takeLog();
    const std::vector<port_io_mock::Access> expected = {
        {true, 0xCF8, 0x8000203C, 32}, {false, 0xCFD, 0x01, 8},
        {true, 0xCF8, 0x80002000, 32}, {false, 0xCFE, 0x8406, 16},
        {true, 0xCF8, 0x8000203C, 32}, {true, 0xCFC, 0x05, 8},
        {true, 0xCF8, 0x80002000, 32}, {false, 0xCFC, 0x840610E8, 32},
    };
    EXPECT_EQ(log, expected) << port_io_mock::describe(log);
    EXPECT_EQ(fake->at(kKvaser).bytes[reg::kInterruptLine], 5);
}

TEST_F(PciTest, MisalignedAndOutOfRangeAccessesAreRefusedWithoutTouchingAPort)
{
    EXPECT_EQ(config.read16(kKvaser, 0x01).status(), Status::InvalidArgument);
    EXPECT_EQ(config.read32(kKvaser, 0x02).status(), Status::InvalidArgument);
    EXPECT_EQ(config.read32(kKvaser, 0x3D).status(), Status::InvalidArgument);
    EXPECT_EQ(config.read8(kKvaser, 256).status(), Status::InvalidArgument);
    EXPECT_EQ(config.read16(kKvaser, 255).status(), Status::InvalidArgument);
    EXPECT_EQ(config.read32(kKvaser, 256).status(), Status::InvalidArgument);
    EXPECT_EQ(config.write16(kKvaser, 0x3D, 0), Status::InvalidArgument);
    EXPECT_EQ(config.write32(kKvaser, 0x12, 0), Status::InvalidArgument);
    EXPECT_EQ(config.write8(kKvaser, 0x100, 0), Status::InvalidArgument);
    EXPECT_EQ(config.read16({0, 32, 0}, 0).status(), Status::InvalidArgument) << "device numbers stop at 31";
    EXPECT_EQ(config.read16({0, 0, 8}, 0).status(), Status::InvalidArgument) << "function numbers stop at 7";
    EXPECT_EQ(config.updateCommand({0, 40, 0}, reg::kCommandIoSpace, 0), Status::InvalidArgument);
    EXPECT_TRUE(port_io_mock::takeLog().empty());
    // The last register of each width is still reachable.
    EXPECT_TRUE(config.read8(kKvaser, 255).ok());
    EXPECT_TRUE(config.read16(kKvaser, 254).ok());
    EXPECT_TRUE(config.read32(kKvaser, 252).ok());
}

TEST_F(PciTest, AnAbsentFunctionReadsAllOnes)
{
    EXPECT_EQ(config.read16({0, 7, 0}, reg::kVendorId).value(), reg::kVendorNone);
    EXPECT_EQ(config.read32({0, 7, 0}, reg::kBar0).value(), 0xFFFFFFFFu);
}

TEST_F(PciTest, UpdateCommandSetsAndClearsOnlyTheNamedBits)
{
    fake->at(kKvaser).store(reg::kCommand, 2, reg::kCommandBusMaster | reg::kCommandInterruptDisable);
    EXPECT_EQ(config.updateCommand(kKvaser, reg::kCommandIoSpace, reg::kCommandInterruptDisable), Status::Ok);
    EXPECT_EQ(fake->at(kKvaser).command(), reg::kCommandIoSpace | reg::kCommandBusMaster);
    const auto log = port_io_mock::takeLog();
    ASSERT_EQ(log.size(), 4u) << port_io_mock::describe(log);
    EXPECT_EQ(log[1].width, 16) << "a word access: the status register beside it clears bits written with ones";
    EXPECT_EQ(log[3].width, 16);
}

TEST_F(PciTest, FunctionConfigKeepsTheFirstRefusalAndStopsWriting)
{
    pci::FunctionConfig function(config, kKvaser);
    EXPECT_EQ(function.read16(reg::kVendorId), 0x10E8);
    EXPECT_EQ(function.read32(0x3E), 0xFFFFFFFFu) << "refused: misaligned";
    function.write8(reg::kInterruptLine, 3);
    EXPECT_EQ(function.read8(reg::kInterruptPin), 0xFF) << "nothing is read after a refusal";
    EXPECT_EQ(function.status(), Status::InvalidArgument);
    EXPECT_EQ(fake->at(kKvaser).bytes[reg::kInterruptLine], 11) << "nothing is written after a refusal";
}

// -- enumeration ---------------------------------------------------------------

TEST_F(PciTest, ScanFindsEveryFunctionOfBusZeroInAddressOrder)
{
    Device devices[Enumerator::kMaxFunctions];
    const size_t found = Enumerator(config).scan(devices, Enumerator::kMaxFunctions);
    const std::vector<Address> expected = {kHostBridge, kIsaBridge, kIde,      kAcpi,    kVga,      kNvme,
                                           kKvaser,     kNic,       kPciBridge, kVirtio0, kVirtio1, kLastSlot};
    ASSERT_EQ(found, expected.size());
    for (size_t i = 0; i < found; ++i) {
        EXPECT_EQ(devices[i].address, expected[i]) << "entry " << i;
    }
}

TEST_F(PciTest, FunctionsOneToSevenAreAskedOnlyOfMultiFunctionDevices)
{
    // The NIC answers every function number, as a single-function device
    // that ignores it does; without the multi-function bit it is found once.
    Device devices[Enumerator::kMaxFunctions];
    const size_t found = Enumerator(config).scan(devices, Enumerator::kMaxFunctions);
    size_t nics = 0;
    for (size_t i = 0; i < found; ++i) {
        nics += devices[i].deviceId == 0x100E ? 1 : 0;
    }
    EXPECT_EQ(nics, 1u);
    EXPECT_TRUE(Enumerator(config).read({0, 5, 3}).ok()) << "the alias is there when asked directly";
}

TEST_F(PciTest, ScanSaysHowManyFunctionsThereAreWhenTheyDoNotAllFit)
{
    Device devices[3];
    EXPECT_EQ(Enumerator(config).scan(devices, 3), 12u);
    EXPECT_EQ(devices[2].address, kIde);
}

TEST_F(PciTest, AnEmptyBusIsScannedWithOneReadPerDevice)
{
    port_io_mock::reset();
    fake = std::make_unique<FakeConfigSpace>();
    Device devices[4];
    EXPECT_EQ(Enumerator(config).scan(devices, 4), 0u);
    EXPECT_EQ(port_io_mock::takeLog().size(), 2u * reg::kDevicesPerBus) << "an address and a vendor read per slot";
}

TEST_F(PciTest, ReadGivesIdentityClassHeaderAndInterrupt)
{
    const Device acpi = device(kAcpi);
    EXPECT_EQ(acpi.vendorId, 0x8086);
    EXPECT_EQ(acpi.deviceId, 0x7113);
    EXPECT_EQ(acpi.revision, 0x02);
    EXPECT_EQ(acpi.classCode, 0x068000u);
    EXPECT_EQ(acpi.baseClass(), 0x06);
    EXPECT_EQ(acpi.subClass(), 0x80);
    EXPECT_EQ(acpi.programmingInterface(), 0x00);
    EXPECT_EQ(acpi.interruptLine, 9);
    EXPECT_EQ(acpi.interruptPin, reg::kInterruptPinA);
    EXPECT_FALSE(acpi.multiFunction) << "only function 0 carries the bit";

    const Device isa = device(kIsaBridge);
    EXPECT_TRUE(isa.multiFunction);
    EXPECT_EQ(isa.headerType, reg::kHeaderTypeDevice);
    EXPECT_EQ(isa.interruptLine, reg::kInterruptLineUnknown);

    const Device kvaser = device(kKvaser);
    EXPECT_EQ(kvaser.subsystemVendorId, 0x10E8);
    EXPECT_EQ(kvaser.subsystemId, 0x8406);
    EXPECT_EQ(kvaser.barCount(), 6u);

    const Device bridge = device(kPciBridge);
    EXPECT_EQ(bridge.headerType, reg::kHeaderTypeBridge);
    EXPECT_EQ(bridge.barCount(), 2u);
    EXPECT_EQ(bridge.subsystemVendorId, 0) << "a bridge has no subsystem registers";
}

TEST_F(PciTest, ReadOfAnEmptySlotIsNotFoundAndOfABadAddressInvalid)
{
    EXPECT_EQ(Enumerator(config).read({0, 7, 0}).status(), Status::NotFound);
    EXPECT_EQ(Enumerator(config).read({0, 1, 2}).status(), Status::NotFound);
    EXPECT_EQ(Enumerator(config).read({0, 32, 0}).status(), Status::InvalidArgument);
}

TEST_F(PciTest, FindCountsMatchesInAddressOrder)
{
    const Enumerator enumerator(config);
    const Result<Device> kvaser = enumerator.find(0x10E8, 0x8406);
    ASSERT_TRUE(kvaser.ok());
    EXPECT_EQ(kvaser.value().address, kKvaser);
    EXPECT_EQ(enumerator.find(0x10E8, 0x8406, 1).status(), Status::NotFound);
    EXPECT_EQ(enumerator.find(0x1AF4, 0x1000, 0).value().address, kVirtio0);
    EXPECT_EQ(enumerator.find(0x1AF4, 0x1000, 1).value().address, kVirtio1);
    EXPECT_EQ(enumerator.find(0x8086, 0x7010).value().address, kIde) << "functions past 0 are found";
    EXPECT_EQ(enumerator.find(0x8086, 0x2918).value().address, kLastSlot);
    EXPECT_EQ(enumerator.find(0xDEAD, 0xBEEF).status(), Status::NotFound);
}

// -- BARs ----------------------------------------------------------------------

TEST_F(PciTest, AnIoBarIsDecodedAndSized)
{
    const Result<Bar> bar = Bar::probe(config, device(kKvaser), 1);
    ASSERT_TRUE(bar.ok()) << dcos::statusName(bar.status());
    EXPECT_EQ(bar.value().kind, Bar::Kind::Io);
    EXPECT_EQ(bar.value().base, 0xC080u);
    EXPECT_EQ(bar.value().size, 0x80u);
    EXPECT_EQ(bar.value().registers, 1);
    EXPECT_FALSE(bar.value().prefetchable);
}

TEST_F(PciTest, AnIoBarWithItsUpperHalfHardwiredToZeroIsSizedAllTheSame)
{
    const Result<Bar> bar = Bar::probe(config, device(kIde), 4);
    ASSERT_TRUE(bar.ok());
    EXPECT_EQ(bar.value().kind, Bar::Kind::Io);
    EXPECT_EQ(bar.value().base, 0xC140u);
    EXPECT_EQ(bar.value().size, 16u);
}

TEST_F(PciTest, SizingTurnsDecodeOffMeanwhileAndPutsEverythingBack)
{
    FakeConfigSpace::Function& vga = fake->at(kVga);
    const uint32_t before = vga.bar(0);
    const uint16_t command = vga.command();
    const Result<Bar> bar = Bar::probe(config, device(kVga), 0);
    ASSERT_TRUE(bar.ok());
    EXPECT_EQ(vga.sizings, 1u);
    EXPECT_EQ(vga.commandWhenSized, reg::kCommandBusMaster) << "decode off, bus mastering left alone";
    EXPECT_EQ(vga.bar(0), before);
    EXPECT_EQ(vga.command(), command);
    EXPECT_EQ(bar.value().kind, Bar::Kind::Memory32);
    EXPECT_EQ(bar.value().base, 0xFD000000u);
    EXPECT_EQ(bar.value().size, 16u << 20);
    EXPECT_TRUE(bar.value().prefetchable);

    const Result<Bar> registers = Bar::probe(config, device(kVga), 2);
    ASSERT_TRUE(registers.ok());
    EXPECT_EQ(registers.value().base, 0xFEBF0000u);
    EXPECT_EQ(registers.value().size, 4096u);
    EXPECT_FALSE(registers.value().prefetchable);
}

TEST_F(PciTest, ASixtyFourBitBarBelowFourGibTakesTwoRegisters)
{
    FakeConfigSpace::Function& nvme = fake->at(kNvme);
    const Result<Bar> bar = Bar::probe(config, device(kNvme), 0);
    ASSERT_TRUE(bar.ok());
    EXPECT_EQ(bar.value().kind, Bar::Kind::Memory64);
    EXPECT_EQ(bar.value().base, 0xFEBF4000u);
    EXPECT_EQ(bar.value().size, 16u * 1024);
    EXPECT_EQ(bar.value().registers, 2);
    EXPECT_EQ(nvme.bar(0), 0xFEBF4000u | reg::kBarMemoryType64);
    EXPECT_EQ(nvme.bar(1), 0u) << "the upper half is put back";
    EXPECT_EQ(nvme.sizings, 2u) << "both halves are sized";
    EXPECT_EQ(nvme.command(), reg::kCommandMemorySpace);
}

TEST_F(PciTest, ASixtyFourBitBarAboveFourGibIsRefusedAndPutBack)
{
    FakeConfigSpace::Function& nvme = fake->at(kNvme);
    EXPECT_EQ(Bar::probe(config, device(kNvme), 2).status(), Status::NotSupported);
    EXPECT_EQ(nvme.bar(2), reg::kBarMemoryType64 | reg::kBarMemoryPrefetchable);
    EXPECT_EQ(nvme.bar(3), 0x8u);
    EXPECT_EQ(nvme.command(), reg::kCommandMemorySpace);
}

TEST_F(PciTest, ASixtyFourBitBarInTheLastRegisterIsRefusedUntouched)
{
    EXPECT_EQ(Bar::probe(config, device(kNvme), 5).status(), Status::NotSupported);
    EXPECT_EQ(fake->at(kNvme).sizings, 0u);
}

TEST_F(PciTest, AnUnimplementedBarIsKindNone)
{
    const Result<Bar> bar = Bar::probe(config, device(kHostBridge), 0);
    ASSERT_TRUE(bar.ok());
    EXPECT_EQ(bar.value().kind, Bar::Kind::None);
    EXPECT_EQ(bar.value().size, 0u);
}

TEST_F(PciTest, ABarTheHeaderDoesNotHaveIsInvalid)
{
    EXPECT_EQ(Bar::probe(config, device(kKvaser), 6).status(), Status::InvalidArgument);
    EXPECT_EQ(Bar::probe(config, device(kPciBridge), 2).status(), Status::InvalidArgument);
    EXPECT_TRUE(Bar::probe(config, device(kPciBridge), 1).ok());
}

TEST_F(PciTest, AReservedMemoryTypeIsRefused)
{
    fake->at(kVga).store(reg::kBar0 + 4, 4, 0x6); // Type 11.
    EXPECT_EQ(Bar::probe(config, device(kVga), 1).status(), Status::NotSupported);
}

} // namespace
