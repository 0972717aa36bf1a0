// The system agent's console command: devices, the installed drivers (seed 7.3.2, 8.3).
#include <dcos/internal/DeviceManager.hpp>
#include <dcos/internal/IdText.hpp>

#include <shell/Shell.hpp>

namespace dcos::internal {

namespace {

const char* visibilityName(Visibility visibility)
{
    switch (visibility) {
    case Visibility::Local: return "local";
    case Visibility::Regional: return "regional";
    case Visibility::Global: return "global";
    }
    return "?";
}

// Each device is copied under the agent's lock and printed after it, so the
// slow console never runs with interrupts disabled.
shell::CommandResult devices(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    DeviceManager& manager = deviceManager();
    shell.print("id          name             open  owner       visibility\r\n");
    const size_t active = manager.activeCount();
    for (size_t slot = 0; slot < active; ++slot) {
        DeviceInfo info;
        if (!manager.snapshot(slot, info)) {
            continue;
        }
        shell.print("%-10s  %-15s  %4lu  ", internal::IdText(info.id).c_str(),
                    info.name[0] != '\0' ? info.name : "-", static_cast<unsigned long>(info.openCount));
        shell.print("%-10s  %s\r\n", info.owner.isNull() ? "system" : internal::IdText(info.owner).c_str(),
                    visibilityName(info.visibility));
    }
    shell.print("%lu of %lu device slots used, %lu reserved\r\n", static_cast<unsigned long>(manager.usedCount()),
                static_cast<unsigned long>(active), static_cast<unsigned long>(DeviceManager::kCapacity));
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(devicesCommand, "devices", "list the installed device drivers", "devices",
                            "  id: the object id, 0x and eight hex digits in every listing and report; name: - when unnamed\r\n"
                            "  open: how many opens are outstanding; owner: the installing task, or system\r\n"
                            "  visibility: local (this node), regional (this controller's nodes) or global (every node)",
                            devices);

} // namespace dcos::internal
