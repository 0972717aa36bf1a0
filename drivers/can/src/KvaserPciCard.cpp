#include <sja1000/KvaserPciCard.hpp>
#include <sja1000/Sja1000Chip.hpp>

#include <pci/Bar.hpp>
#include <pci/ConfigSpace.hpp>
#include <pci/Enumerator.hpp>

namespace sja1000 {

using dcos::Result;
using dcos::Status;

namespace {

/// x86 I/O space: 64 KiB of ports.
constexpr uint32_t kPortSpaceSize = 0x10000;

// BAR @p index of @p device, checked to be an I/O BAR the BIOS placed
// inside port space, decoding at least @p needed ports. A refusal fills in
// @p problem.
Result<pci::Bar> ioBar(const pci::ConfigSpace& config, const pci::Device& device, unsigned index, uint32_t needed,
                       KvaserPciProblem& problem)
{
    problem.bar = static_cast<uint8_t>(index);
    const Result<pci::Bar> bar = pci::Bar::probe(config, device, index);
    if (!bar.ok()) {
        problem.fault = KvaserPciFault::BarUnreadable;
        return bar.status();
    }
    if (bar.value().kind != pci::Bar::Kind::Io) {
        problem.fault = KvaserPciFault::BarNotIo;
        return Status::WrongType;
    }
    if (bar.value().size < needed) {
        problem.fault = KvaserPciFault::BarTooSmall;
        problem.size = bar.value().size;
        problem.needed = needed;
        return Status::NotSupported;
    }
    // Port 0 is the DMA controller's: a BAR there is one the BIOS left
    // unassigned, and using it would reach another device.
    if (bar.value().base == 0 || bar.value().base + needed > kPortSpaceSize) {
        problem.fault = KvaserPciFault::BarUnassigned;
        return Status::NotSupported;
    }
    return bar;
}

} // namespace

Result<KvaserPciCard> KvaserPciCard::probe(const pci::ConfigSpace& config, unsigned index, KvaserPciProblem* problem)
{
    KvaserPciProblem ignored;
    KvaserPciProblem& report = problem != nullptr ? *problem : ignored;
    report = KvaserPciProblem{};

    const Result<pci::Device> found = pci::Enumerator(config).find(kVendorId, kDeviceId, index);
    if (!found.ok()) {
        report.fault = KvaserPciFault::NoCard;
        return found.status();
    }
    const pci::Device& device = found.value();

    // Every check comes before the first write the card keeps, so a card
    // refused here is left as the BIOS left it (sizing a BAR puts it back).
    const Result<pci::Bar> bridge = ioBar(config, device, kBridgeBar, kBridgeWindowSize, report);
    if (!bridge.ok()) {
        return bridge.status();
    }
    const Result<pci::Bar> chips = ioBar(config, device, kChannelBar, reg::kWindowSize, report);
    if (!chips.ok()) {
        return chips.status();
    }
    const Result<pci::Bar> xilinx = ioBar(config, device, kXilinxBar, kXilinxWindowSize, report);
    if (!xilinx.ok()) {
        return xilinx.status();
    }
    report.bar = 0;
    // The controller needs its interrupt: a pin the BIOS routed to no IRQ
    // (255, LB 6.2.4) leaves the chips with no way to be heard.
    if (device.interruptPin < pci::reg::kInterruptPinA || device.interruptPin > pci::reg::kInterruptPinD ||
        device.interruptLine >= pci::reg::kInterruptLineLimit) {
        report.fault = KvaserPciFault::NoInterrupt;
        return Status::NotSupported;
    }

    // I/O decode on, and INTx# allowed: the BIOS may leave a card it has no
    // driver for with either off, as Linux's pci_enable_device turns both
    // the same way. The card does no DMA, so bus mastering stays as found.
    const Status enabled = config.updateCommand(device.address, pci::reg::kCommandIoSpace,
                                                pci::reg::kCommandInterruptDisable);
    if (enabled != Status::Ok) {
        return enabled;
    }

    KvaserPciCard card;
    card.bridge_ = arch_x86::IoWindow::ports(static_cast<uint16_t>(bridge.value().base), kBridgeWindowSize);
    card.channelBase_ = static_cast<uint16_t>(chips.value().base);
    card.interruptLine_ = device.interruptLine;
    card.interruptPin_ = device.interruptPin;
    card.bus_ = device.address.bus;
    card.device_ = device.address.device;
    card.function_ = device.address.function;

    card.bridge_.write32(kPassThruConfiguration, kPassThruSetting);
    const arch_x86::IoWindow logic =
        arch_x86::IoWindow::ports(static_cast<uint16_t>(xilinx.value().base), kXilinxWindowSize);
    card.xilinxVersion_ = static_cast<uint8_t>(logic.read8(kXilinxVersionRegister) >> kXilinxVersionShift);

    // The chips sit one after another from the start of BAR1, as many as
    // the card carries: the first position where none answers ends them,
    // as Linux's number_of_sja1000_chip counts them. The chip core's own
    // probe is the test (it leaves each chip in reset mode, PeliCAN).
    unsigned fit = chips.value().size / kChannelStride;
    if (fit > kMaxChannels) {
        fit = kMaxChannels;
    }
    unsigned channels = 0;
    while (channels < fit) {
        const Sja1000Chip chip(arch_x86::IoWindow::ports(
            static_cast<uint16_t>(card.channelBase_ + channels * kChannelStride), reg::kWindowSize));
        if (chip.probe() != Status::Ok) {
            break;
        }
        ++channels;
    }
    if (channels == 0) {
        report.fault = KvaserPciFault::NoChannel;
        return Status::NotFound;
    }
    card.channels_ = static_cast<uint8_t>(channels);
    return card;
}

Status KvaserPciCard::enableInterrupt() const
{
    if (!present()) {
        return Status::NotFound;
    }
    // The other INTCSR bits go back as read: the same read-modify-write
    // Linux's kvaser_pci_enable_irq makes, so whatever else the S5920 was
    // set up for is kept.
    const uint32_t control = bridge_.read32(kInterruptControl);
    bridge_.write32(kInterruptControl, control | kAddOnInterruptEnable);
    return Status::Ok;
}

Status KvaserPciCard::disableInterrupt() const
{
    if (!present()) {
        return Status::NotFound;
    }
    const uint32_t control = bridge_.read32(kInterruptControl);
    bridge_.write32(kInterruptControl, control & ~kAddOnInterruptEnable);
    return Status::Ok;
}

bool KvaserPciCard::interruptAsserted() const
{
    return present() && (bridge_.read32(kInterruptControl) & kInterruptAsserted) != 0;
}

} // namespace sja1000
