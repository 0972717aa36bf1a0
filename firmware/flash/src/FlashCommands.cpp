// The `flash` console command: what the flash service (FlashService.hpp)
// knows and has done, for an engineer and the lab's tests.
//
//   flash        the service's state, then one "  name value" line per counter
#include <flash/FlashService.hpp>

#include <boot/CardLayout.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace flash {

namespace {

shell::CommandResult flashCommand(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const FlashServiceState s = flashServiceState();
    if (!s.running) {
        shell.print("flash: the service is not running\r\n");
        return shell::CommandResult::Failed;
    }
    shell.print("flash: service running, %u trusted key%s%s%s\r\n", unsigned(s.keys), s.keys == 1 ? "" : "s",
                s.problem != nullptr ? "; images cannot be taken: " : "", s.problem != nullptr ? s.problem : "");
    if (s.runningSlot != 0xFF) {
        shell.print("flash: this node runs a trial from slot %s: a new image waits for its confirmation\r\n",
                    boot::card::slotName(s.runningSlot));
    }
    if (s.can.connections != 0) {
        shell.print("flash: last host CAN node %u on interface %u\r\n", unsigned(s.peer), unsigned(s.interface));
    }
    const struct {
        const char* name;
        uint32_t value;
    } counters[] = {
        {"requests", s.can.requests},   {"replies", s.can.replies},     {"aborted", s.can.aborted},
        {"ignored", s.can.ignored},     {"connections", s.can.connections}, {"queued", s.queued},
        {"dropped", s.dropped},         {"send-failures", s.sendFailures},
    };
    for (const auto& counter : counters) {
        shell.print("  %s %lu\r\n", counter.name, static_cast<unsigned long>(counter.value));
    }
    return shell::CommandResult::Ok;
}

} // namespace

} // namespace flash

DCOS_SHELL_COMMAND(flashCommandEntry, "flash", "show the flash service: keys, the last host, its counters", "flash",
                   flash::flashCommand);
