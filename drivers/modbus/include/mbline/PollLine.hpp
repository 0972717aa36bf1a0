// The controller's Modbus master on the board's second RS-485 port (COM3),
// running the application's polling schedule (`modbusPolls`) from boot on
// (docs/protocols/modbus.md, "The polling schedule").
#pragma once

namespace shell {
class Shell;
}

namespace mbline {

/// Prints the polling line's settings, counters and one line per entry
/// (the console's `modbus poll`); says so when no schedule runs.
void printPollStatus(shell::Shell& shell);

} // namespace mbline
