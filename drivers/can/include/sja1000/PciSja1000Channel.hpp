// The PCI bus front end of one SJA1000 channel: a chip on a Kvaser PCIcan
// card (sja1000/KvaserPciCard.hpp), reached through its 32 ports in the
// card's BAR1 and heard through the interrupt line the BIOS routed the
// card's INTA# to.
//
// Like IsaSja1000Channel, all it adds to the chip core is where the chip
// is, and one thing more: the card keeps the chips' interrupts to itself
// until its S5920 bridge lets them through, so install() enables that once
// the interrupt service routine is in place, and uninstall() disables it
// before the routine goes. There is no resource manager to ask: the BIOS
// assigned the card's ports and line, and no other card can claim them.
//
// Every chip of a card raises the card's one line, and the system agent
// takes one routine per line (InstallISR says Busy to the second): on a
// card with more than one chip only one channel can be installed until the
// line has a dispatcher that asks each channel in turn. QEMU's card, and
// the dual-Pentium board's, has one chip.
#pragma once

#include <sja1000/KvaserPciCard.hpp>
#include <sja1000/Sja1000Controller.hpp>

namespace sja1000 {

class PciSja1000Channel final : public Sja1000Controller {
public:
    /// Chip @p channel (from 0) of @p card, which KvaserPciCard::probe
    /// made, called @p claimant (static storage). The card's 16 MHz
    /// oscillator times the chip. A channel the card does not have is
    /// refused by install().
    constexpr PciSja1000Channel(const char* claimant, const KvaserPciCard& card, unsigned channel)
        : Sja1000Controller(claimant, windowOf(card, channel), card.interruptLine(), KvaserPciCard::kOscillatorHz),
          card_(card), channel_(channel)
    {
    }

    /// Installs the controller under @p name, then enables the card's
    /// interrupt at its bridge. Privileged. InvalidArgument for a channel
    /// the card does not have; AlreadyExists when installed; Busy when the
    /// line already has a routine (another channel of the card, or
    /// another device on a shared line). Nothing is left installed or
    /// enabled after a failure.
    dcos::Result<dcos::ObjectId> install(const char* name, dcos::Visibility visibility);

    /// Disables the card's interrupt and uninstalls the controller; Busy
    /// while open (the interrupt is then enabled again), NotFound when not
    /// installed.
    dcos::Status uninstall();

    /// The chip's place on the card.
    constexpr unsigned channel() const { return channel_; }
    /// The card the chip is on.
    constexpr const KvaserPciCard& card() const { return card_; }

private:
    // The chip's window, or an empty one (every access to which panics) for
    // a channel the card does not have: install() refuses that channel
    // before anything reaches the chip.
    static constexpr arch_x86::IoWindow windowOf(const KvaserPciCard& card, unsigned channel)
    {
        const dcos::Result<arch_x86::IoWindow> window = card.channelWindow(channel);
        return window.ok() ? window.value() : arch_x86::IoWindow{};
    }

    KvaserPciCard card_;
    unsigned channel_;
};

} // namespace sja1000
