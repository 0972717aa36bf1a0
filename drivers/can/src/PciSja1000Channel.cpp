#include <sja1000/PciSja1000Channel.hpp>

namespace sja1000 {

using dcos::Result;
using dcos::Status;

Result<dcos::ObjectId> PciSja1000Channel::install(const char* name, dcos::Visibility visibility)
{
    if (installed()) {
        return Status::AlreadyExists;
    }
    if (!card_.channelWindow(channel_).ok()) {
        return Status::InvalidArgument;
    }
    // The routine first, then the card's interrupt: a chip whose interrupt
    // is pending from before would otherwise assert a line nobody serves.
    const Result<dcos::ObjectId> installed = installController(name, visibility);
    if (!installed.ok()) {
        return installed;
    }
    const Status enabled = card_.enableInterrupt();
    if (enabled != Status::Ok) {
        (void)uninstallController(); // Just installed and not yet open: it goes.
        return enabled;
    }
    return installed;
}

Status PciSja1000Channel::uninstall()
{
    if (!installed()) {
        return Status::NotFound;
    }
    // The card's interrupt first, then the routine, the reverse of
    // install(); a channel still open keeps both.
    (void)card_.disableInterrupt(); // Cannot fail: install() found the card.
    const Status removed = uninstallController();
    if (removed != Status::Ok) {
        (void)card_.enableInterrupt(); // As above.
    }
    return removed;
}

} // namespace sja1000
