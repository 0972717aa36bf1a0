#include <sja1000/BoardCanChannel.hpp>

#include <iobus/IsaResourceManager.hpp>

#include <new>

namespace sja1000 {

using dcos::Result;
using dcos::Status;

Status BoardCanChannel::placeOnPciCard(const KvaserPciCard& card, unsigned chip)
{
    // A channel that has been installed may still be open, or be named by a
    // network interface: it stays where it is.
    if (everInstalled_ || installed()) {
        return Status::Busy;
    }
    if (!card.channelWindow(chip).ok()) {
        return Status::InvalidArgument;
    }
    // The driver object is made again in place for its card and chip; it
    // holds no resource until installed, so the old one has nothing to undo.
    pci_.~PciSja1000Channel();
    new (&pci_) PciSja1000Channel(name_, card, chip);
    onPci_ = true;
    return Status::Ok;
}

uint16_t BoardCanChannel::basePort() const
{
    if (!onPci_) {
        return isa_.base();
    }
    const Result<arch_x86::IoWindow> window = pci_.card().channelWindow(pci_.channel());
    return window.ok() ? static_cast<uint16_t>(window.value().base()) : 0;
}

Result<dcos::ObjectId> BoardCanChannel::install(dcos::Visibility visibility, runtime::CharacterSink& out)
{
    Result<dcos::ObjectId> installed = Status::NotFound;
    if (onPci_) {
        installed = pci_.install(name_, visibility);
        if (!installed.ok()) {
            const char* why = installed.status() == Status::Busy
                                  ? "another driver has the card's interrupt line"
                                  : dcos::statusName(installed.status());
            runtime::format(out, "error: cannot install %s on the PCI card (irq %u): %s\r\n", name_, pci_.irq(), why);
        }
    } else {
        iobus::IsaConflict conflict;
        installed = isa_.install(name_, visibility, &conflict);
        if (!installed.ok()) {
            if (installed.status() == Status::AlreadyExists) {
                char text[96];
                iobus::IsaResourceManager::describe(conflict, text, sizeof text);
                runtime::format(out, "error: %s\r\n", text);
            } else {
                runtime::format(out, "error: cannot install %s: %s\r\n", name_, dcos::statusName(installed.status()));
            }
        }
    }
    everInstalled_ = everInstalled_ || installed.ok();
    return installed;
}

Status BoardCanChannel::uninstall() { return onPci_ ? pci_.uninstall() : isa_.uninstall(); }

void BoardCanChannel::describePlace(char* text, size_t size) const
{
    if (!onPci_) {
        runtime::formatToBuffer(text, size, "ISA card");
        return;
    }
    const KvaserPciCard& card = pci_.card();
    runtime::formatToBuffer(text, size, "PCI %02x:%02x.%x, Kvaser PCIcan chip %u", card.bus(), card.device(),
                            card.function(), pci_.channel());
}

} // namespace sja1000
