// The `sei` console command: what the configuration protocol's server
// (SeiService.hpp) knows and has done, for an engineer and the lab's tests.
//
//   sei        the node's identity for the protocol, then one "  name value" line per counter
#include <sei/SeiService.hpp>

#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace sei {

namespace {

shell::CommandResult seiCommand(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const SeiServiceState s = seiServiceState();
    if (!s.running) {
        shell.print("sei: the configuration protocol is not served\r\n");
        return shell::CommandResult::Failed;
    }
    shell.print("sei: serial %lu, configuration key %s, queries %s\r\n", static_cast<unsigned long>(s.serial),
                s.hasKey ? "set" : "none (nothing can be changed over the bus)", s.queriesClosed ? "closed" : "open");
    if (s.lockoutSecondsLeft != 0) {
        shell.print("sei: locked out for %u s after %u wrong keys\r\n", unsigned(s.lockoutSecondsLeft),
                    SeiAuthenticator::kBadMacLimit);
    }
    if (s.selected) {
        shell.print("sei: selected: answers on the broadcast address\r\n");
    }
    const struct {
        const char* name;
        uint32_t value;
    } counters[] = {
        {"requests", s.can.own.requests},
        {"replies", s.can.own.replies},
        {"aborted", s.can.own.aborted},
        {"broadcast-requests", s.can.broadcast.requests},
        {"scans", s.can.scans},
        {"scan-answers", s.can.scanAnswers},
        {"ignored", s.can.ignored},
        {"bad-macs", s.badMacs},
    };
    for (const auto& counter : counters) {
        shell.print("  %s %lu\r\n", counter.name, static_cast<unsigned long>(counter.value));
    }
    return shell::CommandResult::Ok;
}

} // namespace

} // namespace sei

DCOS_SHELL_COMMAND(seiCommandEntry, "sei",
                   "show the configuration protocol's server: serial number, key, lockout, counters", "sei",
                   sei::seiCommand);
