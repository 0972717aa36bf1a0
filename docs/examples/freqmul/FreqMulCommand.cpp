// The console command `freqmul`: the waves and the checker's counts, and
// new settings for E_CYCLE and E_DELAY (the seed's initialisation
// parameters of the two blocks, which set the waves' period and shift).
//
//     freqmul                          prints the waves and the checker's counts
//     freqmul set <hz> [shift_deg]     source frequency and phase shift (default 90 degrees)
//
// Settings the node's tick cannot make are refused with the reason, and
// the running waves are left as they are.
#include "FreqMul.hpp"

#include <bsp/Board.hpp>
#include <dcos/Status.hpp>
#include <runtime/Text.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace freqmul {

namespace {

using shell::CommandResult;

unsigned long asUnsigned(uint32_t value) { return static_cast<unsigned long>(value); }

void printWaves(shell::Shell& shell, const SharedState& state)
{
    const WaveSettings& waves = state.applied;
    // Y's duty cycle is shift / 180 degrees, printed in hundredths of a percent.
    const uint32_t dutyHundredths = waves.shiftDegrees * 10000 / 180;
    shell.print("freqmul: source %lu Hz, shift %lu degrees: output %lu Hz, duty %lu.%02lu %%; "
                "tick %lu Hz (%lu ns): half period %lu ticks, shift %lu ticks; generation %lu, rejected %lu, "
                "board %s\r\n",
                asUnsigned(waves.frequencyHz), asUnsigned(waves.shiftDegrees), asUnsigned(2 * waves.frequencyHz),
                asUnsigned(dutyHundredths / 100), asUnsigned(dutyHundredths % 100), asUnsigned(bsp::tickRateHz()),
                static_cast<unsigned long>(bsp::tickPeriodNanoseconds()), asUnsigned(waves.halfPeriodTicks),
                asUnsigned(waves.shiftTicks), asUnsigned(state.generation), asUnsigned(state.rejected),
                dcos::statusName(static_cast<dcos::Status>(state.boardStatus)));
}

void printChecker(shell::Shell& shell, const CheckerStatistics& checker)
{
    shell.print("checker: do writes %lu, write errors %lu, samples %lu, edges A %lu B %lu Y %lu, "
                "xor mismatches %lu, loopback mismatches %lu, read errors %lu\r\n",
                asUnsigned(checker.doWrites), asUnsigned(checker.doWriteErrors), asUnsigned(checker.samples),
                asUnsigned(checker.edges[0]), asUnsigned(checker.edges[1]), asUnsigned(checker.edges[2]),
                asUnsigned(checker.xorMismatches), asUnsigned(checker.loopbackMismatches),
                asUnsigned(checker.readErrors));
}

// Says why the tick cannot make the waves asked for.
void explain(shell::Shell& shell, const SettingsCheck& check, uint32_t tickRateHz, uint32_t frequencyHz,
             uint32_t shiftDegrees)
{
    switch (check.error) {
    case SettingsError::None:
        break;
    case SettingsError::FrequencyZero:
        shell.print("error: the source frequency must be at least 1 Hz\r\n");
        break;
    case SettingsError::HalfPeriodNotWhole:
        shell.print("error: cannot make %lu Hz with the %lu Hz tick: half a period would be %lu/%lu ticks, "
                    "not a whole number (the source frequency must divide %lu Hz)\r\n",
                    asUnsigned(frequencyHz), asUnsigned(tickRateHz), asUnsigned(tickRateHz / 2),
                    asUnsigned(frequencyHz), asUnsigned(tickRateHz / 2));
        break;
    case SettingsError::HalfPeriodTooShort:
        shell.print("error: cannot make %lu Hz with the %lu Hz tick: half a period is 1 tick, which leaves no "
                    "room for a phase shift (at most %lu Hz)\r\n",
                    asUnsigned(frequencyHz), asUnsigned(tickRateHz), asUnsigned(tickRateHz / 4));
        break;
    case SettingsError::ShiftOutOfRange:
        shell.print("error: the phase shift must be from 1 to 179 degrees (0 and 180 make the output "
                    "constant)\r\n");
        break;
    case SettingsError::ShiftNotWhole:
        shell.print("error: cannot shift %lu Hz by %lu degrees with the %lu Hz tick: the shift must be a whole "
                    "number of ticks, a multiple of %lu degrees at this frequency\r\n",
                    asUnsigned(frequencyHz), asUnsigned(shiftDegrees), asUnsigned(tickRateHz),
                    asUnsigned(check.shiftStepDegrees));
        break;
    }
}

CommandResult setWaves(shell::Shell& shell, int argc, char** argv)
{
    unsigned long frequencyHz = 0;
    unsigned long shiftDegrees = kDefaultShiftDegrees;
    if (argc < 3 || argc > 4 || !shell::Shell::parseUnsigned(argv[2], frequencyHz) ||
        (argc == 4 && !shell::Shell::parseUnsigned(argv[3], shiftDegrees))) {
        return CommandResult::UsageError;
    }
    const uint32_t tickRateHz = bsp::tickRateHz();
    const SettingsCheck check =
        checkSettings(tickRateHz, static_cast<uint32_t>(frequencyHz), static_cast<uint32_t>(shiftDegrees));
    if (check.error != SettingsError::None) {
        explain(shell, check, tickRateHz, static_cast<uint32_t>(frequencyHz), static_cast<uint32_t>(shiftDegrees));
        return CommandResult::Failed;
    }
    const dcos::Status requested = requestSettings(check.settings.frequencyHz, check.settings.shiftDegrees);
    if (requested != dcos::Status::Ok) {
        shell.print("error: E_CYCLE did not apply the settings: %s\r\n", dcos::statusName(requested));
        return CommandResult::Failed;
    }
    SharedState state;
    if (readSharedState(state)) {
        printWaves(shell, state);
    }
    return CommandResult::Ok;
}

CommandResult freqmulCommand(shell::Shell& shell, int argc, char** argv)
{
    if (argc >= 2 && runtime::textEquals(argv[1], "set")) {
        return setWaves(shell, argc, argv);
    }
    if (argc != 1) {
        return CommandResult::UsageError;
    }
    SharedState state;
    if (!readSharedState(state)) {
        shell.print("error: the state is locked; try again\r\n");
        return CommandResult::Failed;
    }
    printWaves(shell, state);
    printChecker(shell, state.checker);
    return CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND(freqmulShellCommand, "freqmul", "the frequency multiplier's waves and checker (seed 9.4.1)",
                   "freqmul [set <hz> [shift_degrees]]", freqmulCommand);

} // namespace freqmul
