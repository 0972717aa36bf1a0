// The Kvaser PCIcan front end: finding the card through a fake host
// bridge's configuration space, checking its BARs and interrupt, counting
// its chips, the S5920's interrupt enable, and a PciSja1000Channel brought
// onto the bus against FakeSja1000 chips answering in the card's BAR1, as
// QEMU's kvaser_pci model lays the card out.
#include <sja1000/KvaserPciCard.hpp>
#include <sja1000/BoardCanChannel.hpp>
#include <sja1000/PciSja1000Channel.hpp>

#include <pci/ConfigSpace.hpp>
#include <pci/PciRegisters.hpp>

#include <dcos/SystemAgent.hpp>

#include "../../../firmware/dcos/unit_tests/FakeKernelContext.hpp"
#include "../../iobus/unit_tests/FakeAgents.hpp"
#include "../../pci/unit_tests/FakeConfigSpace.hpp"
#include "FakeSja1000.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <memory>
#include <vector>

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::systemAgent;
using pci_test::FakeConfigSpace;
using sja1000::KvaserPciCard;
using sja1000::KvaserPciFault;
using sja1000::KvaserPciProblem;
using sja1000::PciSja1000Channel;
using sja1000_test::FakeSja1000;
namespace pcireg = pci::reg;
namespace reg = sja1000::reg;

constexpr uint16_t kBridgePorts = 0xC000;
constexpr uint16_t kChipPorts = 0xC080;
constexpr uint16_t kXilinxPorts = 0xC100;
constexpr uint8_t kLine = 11;
constexpr pci::Address kCard{0, 4, 0};

// The S5920's operation registers as QEMU models them: INTCSR and PTCR,
// doubleword accesses only (the model's minimum access size is 4).
class FakeS5920 final : public port_io_mock::Responder {
public:
    FakeS5920() { port_io_mock::attach(kBridgePorts, KvaserPciCard::kBridgeWindowSize, this); }

    uint32_t read(uint16_t offset, int width) override
    {
        narrowAccesses += width != 32 ? 1 : 0;
        if (offset == KvaserPciCard::kInterruptControl) {
            return (interruptControl & ~KvaserPciCard::kInterruptAsserted) |
                   (asserted ? KvaserPciCard::kInterruptAsserted : 0);
        }
        return offset == KvaserPciCard::kPassThruConfiguration ? passThru : 0;
    }

    void write(uint16_t offset, uint32_t value, int width) override
    {
        narrowAccesses += width != 32 ? 1 : 0;
        if (offset == KvaserPciCard::kInterruptControl) {
            interruptControl = value;
        } else if (offset == KvaserPciCard::kPassThruConfiguration) {
            passThru = value;
        }
    }

    uint32_t interruptControl = 0;
    uint32_t passThru = 0;
    bool asserted = false;
    unsigned narrowAccesses = 0;
};

// BAR1: the chips one after another, 0x20 ports each; where the card has
// no chip the ports read zeros and take no writes, as in QEMU's model.
class FakeChipSlots final : public port_io_mock::Responder {
public:
    explicit FakeChipSlots(uint16_t size) { port_io_mock::attach(kChipPorts, size, this); }

    uint32_t read(uint16_t offset, int width) override
    {
        FakeSja1000* chip = chipAt(offset);
        return chip != nullptr ? chip->read(offset % KvaserPciCard::kChannelStride, width) : 0;
    }

    void write(uint16_t offset, uint32_t value, int width) override
    {
        if (FakeSja1000* chip = chipAt(offset)) {
            chip->write(offset % KvaserPciCard::kChannelStride, value, width);
        }
    }

    std::vector<std::unique_ptr<FakeSja1000>> chips;

private:
    FakeSja1000* chipAt(uint16_t offset)
    {
        const size_t index = offset / KvaserPciCard::kChannelStride;
        return index < chips.size() ? chips[index].get() : nullptr;
    }
};

// BAR2: the Xilinx logic, with QEMU's version 13 in register 7's high nibble.
class FakeXilinx final : public port_io_mock::Responder {
public:
    FakeXilinx() { port_io_mock::attach(kXilinxPorts, KvaserPciCard::kXilinxWindowSize, this); }
    uint32_t read(uint16_t offset, int) override { return offset == KvaserPciCard::kXilinxVersionRegister ? 13u << 4 : 0; }
    void write(uint16_t, uint32_t, int) override {}
};

class KvaserPciCardTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        port_io_mock::reset();
        host = std::make_unique<FakeConfigSpace>();
        host->add({0, 0, 0}, 0x8086, 0x1237, 0x060000);
        FakeConfigSpace::Function& card =
            host->add(kCard, KvaserPciCard::kVendorId, KvaserPciCard::kDeviceId, 0xFF0000);
        card.ioBar(0, kBridgePorts, 0x80);
        card.ioBar(1, kChipPorts, 0x80);
        card.ioBar(2, kXilinxPorts, 0x08);
        card.store(pcireg::kInterruptLine, 1, kLine);
        card.store(pcireg::kInterruptPin, 1, pcireg::kInterruptPinA);
        // What a BIOS may leave a card it has no driver for: no decode, INTx# off.
        card.store(pcireg::kCommand, 2, pcireg::kCommandInterruptDisable);
        bridge = std::make_unique<FakeS5920>();
        slots = std::make_unique<FakeChipSlots>(0x80);
        xilinx = std::make_unique<FakeXilinx>();
        addChip();
    }

    FakeSja1000& addChip()
    {
        slots->chips.push_back(std::make_unique<FakeSja1000>());
        return *slots->chips.back();
    }

    FakeConfigSpace::Function& cardFunction() { return host->at(kCard); }

    // Whether any access since the last takeLog() reached a port outside
    // the configuration ports.
    static bool touchedTheCard()
    {
        for (const port_io_mock::Access& access : port_io_mock::takeLog()) {
            if (access.port < pcireg::kConfigAddressPort ||
                access.port >= pcireg::kConfigAddressPort + pcireg::kConfigPortCount) {
                return true;
            }
        }
        return false;
    }

    pci::ConfigSpace config;
    std::unique_ptr<FakeConfigSpace> host;
    std::unique_ptr<FakeS5920> bridge;
    std::unique_ptr<FakeChipSlots> slots;
    std::unique_ptr<FakeXilinx> xilinx;
};

TEST_F(KvaserPciCardTest, ProbeFindsTheCardAndOpensItsWindows)
{
    KvaserPciProblem problem;
    const Result<KvaserPciCard> probed = KvaserPciCard::probe(config, 0, &problem);
    ASSERT_TRUE(probed.ok()) << dcos::statusName(probed.status()) << ": " << kvaserPciFaultName(problem.fault);
    const KvaserPciCard& card = probed.value();
    EXPECT_EQ(problem.fault, KvaserPciFault::None);
    EXPECT_TRUE(card.present());
    EXPECT_EQ(card.channelCount(), 1u) << "QEMU's card: one chip, zeros after it";
    const Result<arch_x86::IoWindow> window = card.channelWindow(0);
    ASSERT_TRUE(window.ok());
    EXPECT_EQ(window.value().space(), arch_x86::IoWindow::Space::Port);
    EXPECT_EQ(window.value().base(), kChipPorts);
    EXPECT_EQ(window.value().size(), reg::kWindowSize);
    EXPECT_EQ(card.channelWindow(1).status(), Status::InvalidArgument);
    EXPECT_EQ(card.bridgeWindow().base(), kBridgePorts);
    EXPECT_EQ(card.bridgeWindow().size(), KvaserPciCard::kBridgeWindowSize);
    EXPECT_EQ(card.interruptLine(), kLine);
    EXPECT_EQ(card.interruptPin(), pcireg::kInterruptPinA);
    EXPECT_EQ(card.bus(), 0);
    EXPECT_EQ(card.device(), 4);
    EXPECT_EQ(card.function(), 0);
    EXPECT_EQ(card.xilinxVersion(), 13);

    EXPECT_EQ(cardFunction().command(), pcireg::kCommandIoSpace) << "I/O decode on, INTx# allowed";
    EXPECT_EQ(bridge->passThru, KvaserPciCard::kPassThruSetting);
    EXPECT_EQ(bridge->interruptControl & KvaserPciCard::kAddOnInterruptEnable, 0u) << "the interrupt stays off";
    EXPECT_EQ(bridge->narrowAccesses, 0u) << "the S5920 takes doublewords only";
    const FakeSja1000& chip = *slots->chips[0];
    EXPECT_NE(chip.mode & reg::kModeReset, 0) << "the chip is left in reset mode";
    EXPECT_NE(chip.clockDivider & reg::kClockDividerPeliCan, 0);
    // The BARs are as the BIOS left them after sizing.
    EXPECT_EQ(cardFunction().bar(0), kBridgePorts | pcireg::kBarSpaceIo);
    EXPECT_EQ(cardFunction().bar(1), kChipPorts | pcireg::kBarSpaceIo);
    EXPECT_EQ(cardFunction().bar(2), kXilinxPorts | pcireg::kBarSpaceIo);
}

TEST_F(KvaserPciCardTest, ChipsAreCountedUpToTheFirstEmptyPosition)
{
    addChip();
    const Result<KvaserPciCard> two = KvaserPciCard::probe(config);
    ASSERT_TRUE(two.ok());
    EXPECT_EQ(two.value().channelCount(), 2u);
    EXPECT_EQ(two.value().channelWindow(1).value().base(), kChipPorts + KvaserPciCard::kChannelStride);

    addChip();
    addChip();
    addChip(); // A fifth the card cannot have: BAR1 holds four.
    const Result<KvaserPciCard> four = KvaserPciCard::probe(config);
    ASSERT_TRUE(four.ok());
    EXPECT_EQ(four.value().channelCount(), KvaserPciCard::kMaxChannels);
    EXPECT_EQ(four.value().channelWindow(3).value().base(), kChipPorts + 3 * KvaserPciCard::kChannelStride);
}

TEST_F(KvaserPciCardTest, ASmallerChipBarHoldsFewerChips)
{
    addChip();
    addChip();
    cardFunction().ioBar(1, kChipPorts, 0x40);
    const Result<KvaserPciCard> card = KvaserPciCard::probe(config);
    ASSERT_TRUE(card.ok());
    EXPECT_EQ(card.value().channelCount(), 2u) << "no chip is looked for past the BAR's end";
}

TEST_F(KvaserPciCardTest, NoCardIsNotFound)
{
    KvaserPciProblem problem;
    EXPECT_EQ(KvaserPciCard::probe(config, 1, &problem).status(), Status::NotFound) << "there is one card";
    EXPECT_EQ(problem.fault, KvaserPciFault::NoCard);

    port_io_mock::reset();
    host = std::make_unique<FakeConfigSpace>();
    host->add({0, 0, 0}, 0x8086, 0x1237, 0x060000);
    EXPECT_EQ(KvaserPciCard::probe(config, 0, &problem).status(), Status::NotFound);
    EXPECT_EQ(problem.fault, KvaserPciFault::NoCard);
    EXPECT_FALSE(touchedTheCard());
}

TEST_F(KvaserPciCardTest, ABarOfTheWrongKindIsRefusedAndTheCardLeftAlone)
{
    cardFunction().memoryBar(1, 0xFEBF1000, 0x80);
    port_io_mock::takeLog();
    KvaserPciProblem problem;
    EXPECT_EQ(KvaserPciCard::probe(config, 0, &problem).status(), Status::WrongType);
    EXPECT_EQ(problem.fault, KvaserPciFault::BarNotIo);
    EXPECT_EQ(problem.bar, KvaserPciCard::kChannelBar);
    EXPECT_FALSE(touchedTheCard());
    EXPECT_EQ(cardFunction().command(), pcireg::kCommandInterruptDisable) << "decode stays as found";
    EXPECT_STREQ(kvaserPciFaultName(problem.fault), "BAR not I/O");
}

TEST_F(KvaserPciCardTest, ABarTooSmallForItsRegistersIsRefused)
{
    cardFunction().ioBar(0, kBridgePorts, 0x40);
    port_io_mock::takeLog();
    KvaserPciProblem problem;
    EXPECT_EQ(KvaserPciCard::probe(config, 0, &problem).status(), Status::NotSupported);
    EXPECT_EQ(problem.fault, KvaserPciFault::BarTooSmall);
    EXPECT_EQ(problem.bar, KvaserPciCard::kBridgeBar);
    EXPECT_EQ(problem.size, 0x40u);
    EXPECT_EQ(problem.needed, KvaserPciCard::kBridgeWindowSize);
    EXPECT_FALSE(touchedTheCard());
    EXPECT_EQ(cardFunction().command(), pcireg::kCommandInterruptDisable);
}

TEST_F(KvaserPciCardTest, ABarTheBiosLeftUnassignedIsRefused)
{
    cardFunction().ioBar(2, 0, 0x08);
    KvaserPciProblem problem;
    EXPECT_EQ(KvaserPciCard::probe(config, 0, &problem).status(), Status::NotSupported);
    EXPECT_EQ(problem.fault, KvaserPciFault::BarUnassigned);
    EXPECT_EQ(problem.bar, KvaserPciCard::kXilinxBar);
}

TEST_F(KvaserPciCardTest, AnUnroutedInterruptIsRefused)
{
    cardFunction().store(pcireg::kInterruptLine, 1, pcireg::kInterruptLineUnknown);
    KvaserPciProblem problem;
    EXPECT_EQ(KvaserPciCard::probe(config, 0, &problem).status(), Status::NotSupported);
    EXPECT_EQ(problem.fault, KvaserPciFault::NoInterrupt);

    cardFunction().store(pcireg::kInterruptLine, 1, kLine);
    cardFunction().store(pcireg::kInterruptPin, 1, pcireg::kInterruptPinNone);
    EXPECT_EQ(KvaserPciCard::probe(config, 0, &problem).status(), Status::NotSupported);
    EXPECT_EQ(problem.fault, KvaserPciFault::NoInterrupt);
    EXPECT_EQ(cardFunction().command(), pcireg::kCommandInterruptDisable);
}

TEST_F(KvaserPciCardTest, ACardWithoutAChipThatAnswersIsNotFound)
{
    slots->chips.clear();
    KvaserPciProblem problem;
    EXPECT_EQ(KvaserPciCard::probe(config, 0, &problem).status(), Status::NotFound);
    EXPECT_EQ(problem.fault, KvaserPciFault::NoChannel);
}

TEST_F(KvaserPciCardTest, TheInterruptEnableIsAReadModifyWriteOfIntcsr)
{
    const Result<KvaserPciCard> probed = KvaserPciCard::probe(config);
    ASSERT_TRUE(probed.ok());
    const KvaserPciCard& card = probed.value();
    bridge->interruptControl = 0x00001F1F; // Mailbox settings the driver must keep.
    port_io_mock::takeLog();

    EXPECT_EQ(card.enableInterrupt(), Status::Ok);
    EXPECT_EQ(bridge->interruptControl, 0x00001F1Fu | KvaserPciCard::kAddOnInterruptEnable);
    const std::vector<port_io_mock::Access> enabling = {
        {false, kBridgePorts + KvaserPciCard::kInterruptControl, 0x00001F1F, 32},
        {true, kBridgePorts + KvaserPciCard::kInterruptControl, 0x00003F1F, 32},
    };
    const auto log = port_io_mock::takeLog();
    EXPECT_EQ(log, enabling) << port_io_mock::describe(log);

    EXPECT_FALSE(card.interruptAsserted());
    bridge->asserted = true;
    EXPECT_TRUE(card.interruptAsserted());
    bridge->asserted = false;

    EXPECT_EQ(card.disableInterrupt(), Status::Ok);
    EXPECT_EQ(bridge->interruptControl, 0x00001F1Fu);
    EXPECT_EQ(bridge->narrowAccesses, 0u);
}

TEST_F(KvaserPciCardTest, ACardNotProbedHasNothingToEnable)
{
    const KvaserPciCard card;
    EXPECT_FALSE(card.present());
    EXPECT_EQ(card.channelCount(), 0u);
    EXPECT_EQ(card.channelWindow(0).status(), Status::InvalidArgument);
    EXPECT_EQ(card.enableInterrupt(), Status::NotFound);
    EXPECT_EQ(card.disableInterrupt(), Status::NotFound);
    EXPECT_FALSE(card.interruptAsserted());
    EXPECT_TRUE(port_io_mock::takeLog().empty());
}

TEST_F(KvaserPciCardTest, TheOscillatorGivesTheCiaRatesExactly)
{
    // 16 MHz: the chip core halves it to the 8 MHz CAN clock Linux names.
    for (const uint32_t rate : sja1000::kCiaBitRates) {
        EXPECT_TRUE(sja1000::BitTimingCalculator::forBitRate(rate, KvaserPciCard::kOscillatorHz).ok()) << rate;
    }
}

// -- a channel on the card -----------------------------------------------------

const ObjectId kSuperUser(dcos::fake::kDefaultNode, dcos::ObjectType::Task, 10);

class PciSja1000ChannelTest : public KvaserPciCardTest {
protected:
    void SetUp() override
    {
        KvaserPciCardTest::SetUp();
        iobus_fake::reset();
        dcos::fake::reset();
        dcos::fake::playSuperUser(kSuperUser);
    }

    void TearDown() override
    {
        dcos::fake::playSuperUser(kSuperUser);
        for (auto& channel : channels) {
            while (systemAgent.Close(channel->id()) == Status::Ok) {
            }
            if (channel->installed()) {
                EXPECT_EQ(channel->uninstall(), Status::Ok);
            }
        }
        EXPECT_TRUE(iobus_fake::installedIsrs().empty()) << "uninstall removes the routine";
    }

    PciSja1000Channel& channelOf(const KvaserPciCard& card, unsigned index)
    {
        channels.push_back(std::make_unique<PciSja1000Channel>("can-pci", card, index));
        return *channels.back();
    }

    KvaserPciCard probe()
    {
        const Result<KvaserPciCard> card = KvaserPciCard::probe(config);
        EXPECT_TRUE(card.ok()) << dcos::statusName(card.status());
        return card.value();
    }

    bool enabledAtTheCard() const
    {
        return (bridge->interruptControl & KvaserPciCard::kAddOnInterruptEnable) != 0;
    }

    std::vector<std::unique_ptr<PciSja1000Channel>> channels;
};

TEST_F(PciSja1000ChannelTest, BringsTheChipOntoTheBusAndHearsItOnTheCardsLine)
{
    PciSja1000Channel& channel = channelOf(probe(), 0);
    EXPECT_EQ(channel.irq(), kLine);
    const Result<ObjectId> id = channel.install("can-pci", dcos::Visibility::Local);
    ASSERT_TRUE(id.ok()) << dcos::statusName(id.status());
    EXPECT_TRUE(enabledAtTheCard());
    ASSERT_EQ(iobus_fake::installedIsrs().size(), 1u);
    EXPECT_EQ(iobus_fake::installedIsrs()[0].line, kLine);

    ASSERT_EQ(systemAgent.Open(id.value()), Status::Ok);
    FakeSja1000& chip = *slots->chips[0];
    EXPECT_EQ(chip.mode & reg::kModeReset, 0) << "bus-on: operating mode";
    EXPECT_NE(chip.interruptEnable & reg::kInterruptReceive, 0);
    const auto timing = sja1000::BitTimingCalculator::decode(chip.btr0, chip.btr1, KvaserPciCard::kOscillatorHz);
    ASSERT_TRUE(timing.ok());
    EXPECT_EQ(timing.value().bitRate, sja1000::Sja1000Controller::kDefaultBitRate);
    sja1000::BusState state{};
    ASSERT_EQ(systemAgent.Control(id.value(), sja1000::Sja1000Controller::kGetState, &state, sizeof state),
              Status::Ok);
    EXPECT_EQ(state.started, 1);

    // A frame from the bus arrives through the card's line.
    const can::CanFrame incoming =
        can::CanFrame::makeData(0x1ABCDE, can::IdFormat::Extended, reinterpret_cast<const uint8_t*>("pci"), 3)
            .value();
    chip.receive(incoming);
    ASSERT_TRUE(iobus_fake::raise(kLine));
    can::CanFrame received{};
    const Result<size_t> read = systemAgent.Read(id.value(), 0, &received, sizeof received);
    ASSERT_TRUE(read.ok());
    ASSERT_EQ(read.value(), sizeof received);
    EXPECT_EQ(received, incoming);

    // And one written goes to the chip in the card's BAR1.
    const can::CanFrame outgoing = can::CanFrame::makeData(0x123, can::IdFormat::Standard, nullptr, 0).value();
    const Result<size_t> written = systemAgent.Write(id.value(), 0, &outgoing, sizeof outgoing);
    ASSERT_TRUE(written.ok());
    EXPECT_EQ(written.value(), sizeof outgoing);
    ASSERT_TRUE(chip.transmitting());
    EXPECT_EQ(chip.transmitted(), outgoing);
}

TEST_F(PciSja1000ChannelTest, UninstallTurnsTheCardsInterruptOffFirst)
{
    PciSja1000Channel& channel = channelOf(probe(), 0);
    const Result<ObjectId> id = channel.install("can-pci", dcos::Visibility::Local);
    ASSERT_TRUE(id.ok());
    ASSERT_EQ(systemAgent.Open(id.value()), Status::Ok);
    EXPECT_EQ(channel.uninstall(), Status::Busy) << "open";
    EXPECT_TRUE(enabledAtTheCard()) << "an open channel keeps its interrupt";
    ASSERT_EQ(systemAgent.Close(id.value()), Status::Ok);
    EXPECT_EQ(channel.uninstall(), Status::Ok);
    EXPECT_FALSE(enabledAtTheCard());
    EXPECT_TRUE(iobus_fake::installedIsrs().empty());
    EXPECT_EQ(channel.uninstall(), Status::NotFound);
}

TEST_F(PciSja1000ChannelTest, AChannelTheCardDoesNotHaveIsRefused)
{
    PciSja1000Channel& channel = channelOf(probe(), 1);
    port_io_mock::takeLog();
    EXPECT_EQ(channel.install("can-pci", dcos::Visibility::Local).status(), Status::InvalidArgument);
    EXPECT_FALSE(channel.installed());
    EXPECT_TRUE(iobus_fake::installedIsrs().empty());
    EXPECT_FALSE(enabledAtTheCard());
    EXPECT_TRUE(port_io_mock::takeLog().empty());

    PciSja1000Channel& unprobed = channelOf(KvaserPciCard{}, 0);
    EXPECT_EQ(unprobed.install("can-pci2", dcos::Visibility::Local).status(), Status::InvalidArgument);
}

TEST_F(PciSja1000ChannelTest, TheSecondChipOfACardCannotTakeTheSharedLineToo)
{
    addChip();
    const KvaserPciCard card = probe();
    ASSERT_EQ(card.channelCount(), 2u);
    PciSja1000Channel& first = channelOf(card, 0);
    PciSja1000Channel& second = channelOf(card, 1);
    ASSERT_TRUE(first.install("can-pci0", dcos::Visibility::Local).ok());
    EXPECT_EQ(second.install("can-pci1", dcos::Visibility::Local).status(), Status::Busy);
    EXPECT_TRUE(enabledAtTheCard()) << "the first channel's interrupt is untouched";
    EXPECT_FALSE(second.installed());
}

// -- the board's channel: the ISA card's until placed on a PCI card -------------

class StringSink final : public runtime::CharacterSink {
public:
    void put(char character) override { text.push_back(character); }
    std::string text;
};

class BoardCanChannelTest : public PciSja1000ChannelTest {
protected:
    void TearDown() override
    {
        dcos::fake::playSuperUser(kSuperUser);
        for (sja1000::BoardCanChannel* channel : {&can0, &can1}) {
            while (systemAgent.Close(channel->id()) == Status::Ok) {
            }
            if (channel->installed()) {
                EXPECT_EQ(channel->uninstall(), Status::Ok);
            }
        }
        PciSja1000ChannelTest::TearDown();
    }

    sja1000::BoardCanChannel can0{"can0", 0x280, 10};
    sja1000::BoardCanChannel can1{"can1", 0x2A0, 11};
    StringSink out;
};

TEST_F(BoardCanChannelTest, AChannelIsTheIsaCardsUntilPlaced)
{
    EXPECT_FALSE(can0.onPciCard());
    EXPECT_EQ(can0.basePort(), 0x280);
    EXPECT_EQ(can0.irq(), 10);
    char place[48];
    can0.describePlace(place, sizeof place);
    EXPECT_STREQ(place, "ISA card");
}

TEST_F(BoardCanChannelTest, PlacedOnTheCardItInstallsThereOnTheCardsLine)
{
    const KvaserPciCard card = probe();
    ASSERT_EQ(can0.placeOnPciCard(card, 0), Status::Ok);
    EXPECT_TRUE(can0.onPciCard());
    EXPECT_EQ(can0.basePort(), kChipPorts);
    EXPECT_EQ(can0.irq(), kLine);
    char place[48];
    can0.describePlace(place, sizeof place);
    EXPECT_STREQ(place, "PCI 00:04.0, Kvaser PCIcan chip 0");

    const Result<ObjectId> id = can0.install(dcos::Visibility::Local, out);
    ASSERT_TRUE(id.ok()) << out.text;
    EXPECT_EQ(can0.id(), id.value());
    EXPECT_TRUE(out.text.empty()) << out.text;
    EXPECT_TRUE(enabledAtTheCard());
    ASSERT_EQ(iobus_fake::installedIsrs().size(), 1u);
    EXPECT_EQ(iobus_fake::installedIsrs()[0].line, kLine);
    EXPECT_EQ(can0.uninstall(), Status::Ok);
    EXPECT_FALSE(enabledAtTheCard());
}

TEST_F(BoardCanChannelTest, AChipTheCardDoesNotHaveLeavesTheChannelWhereItWas)
{
    EXPECT_EQ(can0.placeOnPciCard(probe(), 1), Status::InvalidArgument);
    EXPECT_EQ(can0.placeOnPciCard(KvaserPciCard{}, 0), Status::InvalidArgument);
    EXPECT_FALSE(can0.onPciCard());
    EXPECT_EQ(can0.basePort(), 0x280);
}

TEST_F(BoardCanChannelTest, AChannelOnceInstalledKeepsItsPlace)
{
    const KvaserPciCard card = probe();
    ASSERT_EQ(can0.placeOnPciCard(card, 0), Status::Ok);
    ASSERT_TRUE(can0.install(dcos::Visibility::Local, out).ok()) << out.text;
    EXPECT_EQ(can0.placeOnPciCard(card, 0), Status::Busy) << "installed";
    ASSERT_EQ(can0.uninstall(), Status::Ok);
    EXPECT_EQ(can0.placeOnPciCard(card, 0), Status::Busy) << "a network interface may still name it";
    EXPECT_TRUE(can0.onPciCard());
}

TEST_F(BoardCanChannelTest, TwoChipsOnOneLineSayWhyTheSecondCannotInstall)
{
    addChip();
    const KvaserPciCard card = probe();
    ASSERT_EQ(can0.placeOnPciCard(card, 0), Status::Ok);
    ASSERT_EQ(can1.placeOnPciCard(card, 1), Status::Ok);
    ASSERT_TRUE(can0.install(dcos::Visibility::Local, out).ok()) << out.text;
    EXPECT_EQ(can1.install(dcos::Visibility::Local, out).status(), Status::Busy);
    EXPECT_EQ(out.text, "error: cannot install can1 on the PCI card (irq 11): another driver has the card's "
                        "interrupt line\r\n");
    EXPECT_FALSE(can1.installed());
}

} // namespace
