// One CAN channel of the board as the console's `can` command and the
// network interfaces see it (can0, can1): an SJA1000 wherever this node
// has it. On the ISA 486 board that is a chip of the two-channel ISA card
// at its default jumpers (sja1000/IsaSja1000Channel.hpp). A node that owns
// a PCI bus (node 2 of the dual-Pentium board, bsp::ownsPciBus()) gives
// its channels to the chips of the Kvaser PCIcan cards it finds first
// (sja1000/PciSja1000Channel.hpp), so that can0 is the PCI card's chip
// there and the ISA card's elsewhere, and everything above the driver,
// from `can send` to the remote agent, is the same on both boards.
//
// Where a channel is is decided once, before the first install, by
// placeOnPciCard(); until then, and for ever on the ISA board, it is the
// ISA card's.
#pragma once

#include <sja1000/IsaSja1000Channel.hpp>
#include <sja1000/PciSja1000Channel.hpp>

#include <runtime/Format.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sja1000 {

class BoardCanChannel {
public:
    /// Channel @p name (static storage, also the claimant the resource
    /// manager shows), the ISA card's chip at @p isaBase with line @p isaIrq
    /// until placed on a PCI card.
    constexpr BoardCanChannel(const char* name, uint16_t isaBase, uint8_t isaIrq)
        : name_(name), isa_(name, isaBase, isaIrq), pci_(name, KvaserPciCard{}, 0)
    {
    }

    BoardCanChannel(const BoardCanChannel&) = delete;
    BoardCanChannel& operator=(const BoardCanChannel&) = delete;

    /// Makes the channel chip @p chip of @p card (which KvaserPciCard::probe
    /// made). InvalidArgument for a chip the card does not have; Busy once
    /// the channel has been installed (it keeps its place then).
    dcos::Status placeOnPciCard(const KvaserPciCard& card, unsigned chip);

    /// Whether the channel is a PCI card's chip.
    bool onPciCard() const { return onPci_; }

    /// The chip's driver, ISA or PCI.
    Sja1000Controller& controller() { return onPci_ ? static_cast<Sja1000Controller&>(pci_) : isa_; }
    const Sja1000Controller& controller() const
    {
        return onPci_ ? static_cast<const Sja1000Controller&>(pci_) : isa_;
    }

    bool installed() const { return controller().installed(); }
    dcos::ObjectId id() const { return controller().id(); }
    const char* name() const { return name_; }

    /// The first port of the chip's registers and its interrupt line.
    uint16_t basePort() const;
    uint8_t irq() const { return controller().irq(); }

    /// Installs the driver under the channel's name: for the ISA card with
    /// its ports and line reserved, for a PCI card with the card's
    /// interrupt enabled at its bridge. Privileged. On failure says why on
    /// @p out, naming both claimants of an ISA conflict, and leaves nothing
    /// installed.
    dcos::Result<dcos::ObjectId> install(dcos::Visibility visibility, runtime::CharacterSink& out);

    /// Uninstalls the driver (and releases what install() took); Busy while open.
    dcos::Status uninstall();

    /// Where the chip is, for the console: "ISA card" or "PCI 00:04.0,
    /// Kvaser PCIcan chip 0"; always terminated within @p size.
    void describePlace(char* text, size_t size) const;

private:
    const char* name_;
    IsaSja1000Channel isa_;
    PciSja1000Channel pci_;
    bool onPci_ = false;
    bool everInstalled_ = false;
};

} // namespace sja1000
