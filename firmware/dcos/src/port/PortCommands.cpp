// The message port agent's console command: ports, the queue depth of every
// port and the free message buffers (seed 7.9, 8.3).
#include <dcos/internal/PortManager.hpp>
#include <dcos/internal/IdText.hpp>

#include <shell/Shell.hpp>

namespace dcos::internal {

namespace {

// Each port is copied under the agent's lock and printed after it, so the
// slow console never runs with interrupts disabled.
shell::CommandResult ports(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    shell.print("id          name             order     queued  levels    receiver  owner\r\n");
    const size_t active = PortManager::activeCount();
    for (size_t slot = 0; slot < active; ++slot) {
        PortInfo info;
        if (!PortManager::snapshot(slot, info)) {
            continue;
        }
        shell.print("%-10s  %-15s  %-8s  %6lu  %08lx  %-8s  ", internal::IdText(info.id).c_str(),
                    info.name[0] != '\0' ? info.name : "-", info.order == PortOrder::Fifo ? "fifo" : "priority",
                    static_cast<unsigned long>(info.queued), static_cast<unsigned long>(info.levelBits),
                    info.receiverWaiting ? "waiting" : "-");
        if (info.owner.isNull()) {
            shell.print("system\r\n");
        } else {
            shell.print("%s\r\n", internal::IdText(info.owner).c_str());
        }
    }
    const MessageBufferCounts buffers = PortManager::bufferCounts();
    shell.print("%lu of %lu port slots used; message buffers: %lu free of %lu active, %lu reserved\r\n",
                static_cast<unsigned long>(PortManager::portCount()), static_cast<unsigned long>(active),
                static_cast<unsigned long>(buffers.free), static_cast<unsigned long>(buffers.active),
                static_cast<unsigned long>(buffers.reserved));
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(portsCommand, "ports", "list the message ports and the free message buffers", "ports",
                            "  id: the object id, 0x and eight hex digits in every listing and report; name: - when unnamed\r\n"
                            "  order: fifo or priority; queued: messages waiting to be received\r\n"
                            "  levels: bit n set while priority level n holds messages\r\n"
                            "  receiver: waiting while the owner is blocked in Receive; owner: the owning task, or system",
                            ports);

} // namespace dcos::internal
