// The ISA bus front end of one SJA1000 channel: a port-mapped chip on a
// PC/104 or ISA card, reached as 32 consecutive ports (reg::kWindowSize)
// from the channel's base port, as Linux's sja1000_isa driver addresses it.
//
// All it adds to the chip core is where the chip is: it reserves the
// channel's ports and interrupt line with the ISA resource manager, so a
// conflict with another card names both claimants, and hands the window
// to Sja1000Controller. A two-channel card is two of these, the second at
// base + 0x20 with its own line.
#pragma once

#include <sja1000/IsaCardSettings.hpp>
#include <sja1000/Sja1000Controller.hpp>

#include <iobus/IsaResourceManager.hpp>

namespace sja1000 {

class IsaSja1000Channel final : public Sja1000Controller {
public:
    /// A channel called @p claimant (at most 15 characters, static storage)
    /// at @p base with interrupt line @p irq.
    constexpr IsaSja1000Channel(const char* claimant, uint16_t base, uint8_t irq,
                                uint32_t oscillatorHz = kDefaultOscillatorHz)
        : Sja1000Controller(claimant, arch_x86::IoWindow::ports(base, reg::kWindowSize), irq, oscillatorHz),
          base_(base)
    {
    }

    /// Reserves the ports and the line, then installs the controller under
    /// @p name. Privileged. AlreadyExists with @p conflict filled in when
    /// the resource manager refuses; nothing stays reserved after a failure.
    dcos::Result<dcos::ObjectId> install(const char* name, dcos::Visibility visibility, iobus::IsaConflict* conflict);

    /// Uninstalls the controller and releases the resources; Busy while open.
    dcos::Status uninstall();

    uint16_t base() const { return base_; }

private:
    uint16_t base_;
};

} // namespace sja1000
