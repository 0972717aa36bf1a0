// The Kvaser PCIcan card: one to four SJA1000 channels behind an AMCC S5920
// PCI bridge, the CAN card of the dual-Pentium board and of QEMU's
// `kvaser_pci` device (hw/net/can/can_kvaser_pci.c).
//
// The card has three I/O BARs (QEMU's model, and Linux's kvaser_pci driver,
// drivers/net/can/sja1000/kvaser_pci.c, map the same):
// - BAR0, 128 ports: the S5920's operation registers. Only two matter: the
//   interrupt control/status register INTCSR, whose add-on interrupt enable
//   lets the SJA1000s' interrupt through to the card's INTA#, and the
//   pass-thru configuration register PTCR.
// - BAR1, 128 ports: the SJA1000s, 32 ports (reg::kWindowSize) each, one
//   after another. The real cards carry one, two or four; QEMU's carries
//   one and reads the rest of the BAR as zeros.
// - BAR2, 8 ports: the card's Xilinx logic, whose register 7 holds its
//   version in the high nibble.
//
// probe() finds the card, checks those BARs, turns on its I/O decode and
// counts its channels; the channels themselves are PciSja1000Channel
// objects, each a Sja1000Controller over one chip's window. The BIOS
// assigned the BARs and routed the interrupt, so there is nothing to
// reserve: unlike an ISA card, which sits wherever its switches put it, a
// PCI card cannot collide with another.
//
// Every chip on the card shares the one interrupt line, and the card's
// interrupt stays off at the S5920 until enableInterrupt().
#pragma once

#include <sja1000/Sja1000Registers.hpp>

#include <arch_x86/IoWindow.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace pci {
class ConfigSpace;
}

namespace sja1000 {

/// What KvaserPciCard::probe found wrong, beyond its Status.
enum class KvaserPciFault : uint8_t {
    None = 0,
    NoCard,          ///< No such card on bus 0 (NotFound).
    BarUnreadable,   ///< A BAR could not be decoded or sized (its Status: NotSupported, ...).
    BarNotIo,        ///< A BAR is not an I/O BAR (WrongType).
    BarTooSmall,     ///< A BAR decodes fewer ports than the card's registers take (NotSupported).
    BarUnassigned,   ///< The BIOS left a BAR at port 0, or past the 64 KiB of x86 ports (NotSupported).
    NoInterrupt,     ///< No interrupt pin, or the BIOS routed it to no IRQ (NotSupported).
    NoChannel,       ///< No SJA1000 answers in BAR1 (NotFound).
};

/// A short English name for @p fault, for logs and the shell.
constexpr const char* kvaserPciFaultName(KvaserPciFault fault)
{
    switch (fault) {
    case KvaserPciFault::None: return "none";
    case KvaserPciFault::NoCard: return "no card";
    case KvaserPciFault::BarUnreadable: return "BAR unreadable";
    case KvaserPciFault::BarNotIo: return "BAR not I/O";
    case KvaserPciFault::BarTooSmall: return "BAR too small";
    case KvaserPciFault::BarUnassigned: return "BAR unassigned";
    case KvaserPciFault::NoInterrupt: return "no interrupt";
    case KvaserPciFault::NoChannel: return "no channel";
    }
    return "unknown";
}

/// The details of a failed probe: which fault, at which BAR, and the size
/// found against the size needed where that is the fault.
struct KvaserPciProblem {
    KvaserPciFault fault = KvaserPciFault::None;
    uint8_t bar = 0;     ///< The BAR at fault (Bar* faults).
    uint32_t size = 0;   ///< BarTooSmall: the ports the BAR decodes.
    uint32_t needed = 0; ///< BarTooSmall: the ports the card's registers take there.
};

class KvaserPciCard {
public:
    // Identity: the S5920's vendor (AMCC) and Kvaser's device number, as
    // QEMU's model reports them and Linux's KVASER_PCI_VENDOR_ID1/DEVICE_ID1
    // name them.
    static constexpr uint16_t kVendorId = 0x10E8;
    static constexpr uint16_t kDeviceId = 0x8406;

    // The BARs (QEMU's kvaser_pci_realize; Linux's kvaser_pci_init_one).
    static constexpr unsigned kBridgeBar = 0;  ///< S5920 operation registers.
    static constexpr unsigned kChannelBar = 1; ///< The SJA1000s.
    static constexpr unsigned kXilinxBar = 2;  ///< The Xilinx logic.
    /// Ports of the S5920's operation registers (QEMU's KVASER_PCI_S5920_RANGE,
    /// Linux's PCI_CONFIG_PORT_SIZE).
    static constexpr uint16_t kBridgeWindowSize = 0x80;
    /// Ports from one chip to the next in BAR1 (KVASER_PCI_BYTES_PER_SJA,
    /// Linux's KVASER_PCI_PORT_BYTES).
    static constexpr uint16_t kChannelStride = 0x20;
    /// Chips a card carries at most, the PCIcan-Q's four (Linux's MAX_NO_OF_CHANNELS).
    static constexpr unsigned kMaxChannels = 4;
    /// Ports of the Xilinx logic (KVASER_PCI_XILINX_RANGE, PCI_PORT_XILINX_SIZE).
    static constexpr uint16_t kXilinxWindowSize = 0x08;

    // The S5920's operation registers, doubleword wide: QEMU's model
    // implements them as 4-byte registers (kvaser_pci_s5920_io_ops), and
    // Linux's driver makes no other accesses.
    /// INTCSR, the interrupt control/status register.
    static constexpr uint8_t kInterruptControl = 0x38;
    /// INTCSR bit 13: the add-on interrupt pin (the SJA1000s' wired
    /// interrupt) drives the card's INTA#; clear, the chips' interrupts stay
    /// on the card.
    static constexpr uint32_t kAddOnInterruptEnable = 1u << 13;
    /// INTCSR bit 23: the card asserts its interrupt (read only).
    static constexpr uint32_t kInterruptAsserted = 1u << 23;
    /// PTCR, the pass-thru configuration register.
    static constexpr uint8_t kPassThruConfiguration = 0x60;
    /// What Linux writes to PTCR before using the chips ("assert PTADR#";
    /// with the S5920 in passive mode the other bits do not matter). QEMU's
    /// model ignores the register; the real card needs it.
    static constexpr uint32_t kPassThruSetting = 0x80808080;

    /// The Xilinx register with the version in its high nibble (QEMU's
    /// KVASER_PCI_XILINX_VERINT; its low nibble simulates interrupts).
    static constexpr uint8_t kXilinxVersionRegister = 7;
    static constexpr unsigned kXilinxVersionShift = 4;

    /// The card's oscillator: 16 MHz, of which the SJA1000 makes its 8 MHz
    /// CAN clock (Linux's KVASER_PCI_CAN_CLOCK is 16 MHz / 2). The chip
    /// core's oscillatorHz is the oscillator, not the CAN clock
    /// (BitTimingCalculator halves it), so this is what it is given.
    static constexpr uint32_t kOscillatorHz = 16'000'000;

    static_assert(reg::kWindowSize <= kChannelStride, "one chip's window fits between two chips");

    /// No card; probe() makes real ones.
    constexpr KvaserPciCard() = default;

    /// Finds the @p index-th (from 0) Kvaser PCIcan on bus 0, checks that
    /// its three BARs are I/O BARs the BIOS placed, large enough for the
    /// registers the driver reaches, and that its interrupt is routed;
    /// then enables its I/O decode (and its INTx#, should the BIOS have
    /// disabled it), sets up the S5920's pass-thru, reads the Xilinx
    /// version and counts the SJA1000s that answer (each is left in reset
    /// mode). The card's interrupt stays disabled at the S5920.
    ///
    /// On failure the Status says the kind of problem (NotFound, WrongType,
    /// NotSupported, ...) and @p problem, when given, which one. A card
    /// refused for its BARs or its interrupt is left as it was found; one
    /// without a chip that answers keeps its I/O decode enabled.
    static dcos::Result<KvaserPciCard> probe(const pci::ConfigSpace& config, unsigned index = 0,
                                             KvaserPciProblem* problem = nullptr);

    /// Whether probe() made this card.
    constexpr bool present() const { return channels_ != 0; }
    /// The SJA1000s that answered, 1 to kMaxChannels; 0 without a card.
    constexpr unsigned channelCount() const { return channels_; }

    /// The window of chip @p channel's registers, reg::kWindowSize ports;
    /// InvalidArgument for a channel the card does not have.
    constexpr dcos::Result<arch_x86::IoWindow> channelWindow(unsigned channel) const
    {
        if (channel >= channels_) {
            return dcos::Status::InvalidArgument;
        }
        return arch_x86::IoWindow::ports(static_cast<uint16_t>(channelBase_ + channel * kChannelStride),
                                         reg::kWindowSize);
    }

    /// The interrupt controller input the BIOS routed the card's INTA# to
    /// (the configuration header's Interrupt Line): an IRQ of the 8259
    /// pair, 0-15. Every channel of the card raises it.
    constexpr uint8_t interruptLine() const { return interruptLine_; }
    /// The pin the card uses, 1 for INTA# (the Interrupt Pin register).
    constexpr uint8_t interruptPin() const { return interruptPin_; }

    constexpr uint8_t bus() const { return bus_; }
    constexpr uint8_t device() const { return device_; }
    constexpr uint8_t function() const { return function_; }

    /// The Xilinx logic's version (13 in QEMU's model; Linux's driver
    /// presumes 14).
    constexpr uint8_t xilinxVersion() const { return xilinxVersion_; }

    /// The S5920's operation registers, kBridgeWindowSize ports from BAR0.
    constexpr const arch_x86::IoWindow& bridgeWindow() const { return bridge_; }

    /// Lets the chips' interrupts through to the card's interrupt line:
    /// sets the add-on interrupt enable in INTCSR, keeping its other bits.
    /// Install the interrupt service routine first. NotFound without a card.
    dcos::Status enableInterrupt() const;
    /// Keeps the chips' interrupts on the card: clears the add-on interrupt
    /// enable in INTCSR, keeping its other bits. NotFound without a card.
    dcos::Status disableInterrupt() const;
    /// Whether the card asserts its interrupt now (INTCSR bit 23): what an
    /// interrupt service routine on a shared line asks first. False
    /// without a card.
    bool interruptAsserted() const;

private:
    arch_x86::IoWindow bridge_{};
    uint16_t channelBase_ = 0;
    uint8_t channels_ = 0;
    uint8_t interruptLine_ = 0;
    uint8_t interruptPin_ = 0;
    uint8_t bus_ = 0;
    uint8_t device_ = 0;
    uint8_t function_ = 0;
    uint8_t xilinxVersion_ = 0;
};

} // namespace sja1000
