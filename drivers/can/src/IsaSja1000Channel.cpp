#include <sja1000/IsaSja1000Channel.hpp>

namespace sja1000 {

using dcos::Result;
using dcos::Status;

Result<dcos::ObjectId> IsaSja1000Channel::install(const char* name, dcos::Visibility visibility,
                                                  iobus::IsaConflict* conflict)
{
    if (installed()) {
        return Status::AlreadyExists;
    }
    iobus::IsaResourceManager& resources = iobus::isaResources();
    const Status reserved = resources.reserve(claimant(), base_, reg::kWindowSize, irq(), conflict);
    if (reserved != Status::Ok) {
        return reserved;
    }
    const Result<dcos::ObjectId> installed = installController(name, visibility);
    if (!installed.ok()) {
        resources.release(claimant());
    }
    return installed;
}

Status IsaSja1000Channel::uninstall()
{
    const Status removed = uninstallController();
    if (removed == Status::Ok) {
        iobus::isaResources().release(claimant());
    }
    return removed;
}

} // namespace sja1000
