// The console command `drive`: what the control task read and wrote last.
#include "ModbusDrive.hpp"

#include <dcos/Status.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace drive {

namespace {

shell::CommandResult driveCommand(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    shell.print("drive: request %lu rpm run %lu, setpoint %lu rpm; speed %lu rpm, temperature %lu.%lu C, "
                "at speed %lu, answering %lu\r\n",
                static_cast<unsigned long>(state.requested), static_cast<unsigned long>(state.run),
                static_cast<unsigned long>(state.setpoint), static_cast<unsigned long>(state.speed),
                static_cast<unsigned long>(state.temperature / 10), static_cast<unsigned long>(state.temperature % 10),
                static_cast<unsigned long>(state.atSpeed), static_cast<unsigned long>(state.answering));
    shell.print("control: cycles %lu, drive pages %lu, losses %lu, failures %lu (last: %s)\r\n",
                static_cast<unsigned long>(state.cycles), static_cast<unsigned long>(state.drivePages),
                static_cast<unsigned long>(state.losses), static_cast<unsigned long>(state.failures),
                dcos::statusName(static_cast<dcos::Status>(state.lastFailure)));
    return shell::CommandResult::Ok;
}

} // namespace

} // namespace drive

DCOS_SHELL_COMMAND(driveShellCommand, "drive", "what the modbus_drive control task read and wrote last", "drive",
                   drive::driveCommand);
