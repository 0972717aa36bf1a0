// The console command `iobus`: probe, read, write, gain and bring-up of the
// multi-function I/O board (issue 5, items 3 and 5; docs/iobus/driver.md).
//
// The console owns one board object, "mfio0". Every subcommand that takes a
// base port and a line moves the board there first (reserving the new
// resources, which may conflict), installs it with the system agent when it
// is not installed yet, and opens it only for the duration of the command.
#include <iobus/AnalogScaling.hpp>
#include <iobus/Bringup.hpp>
#include <iobus/IsaResourceManager.hpp>
#include <iobus/MfioBoard.hpp>
#include <iobus/MfioClient.hpp>
#include <iobus/MfioRegisters.hpp>

#include <bsp/Board.hpp>
#include <dcos/SystemAgent.hpp>
#include <shell/Shell.hpp>

namespace iobus {

namespace {

using dcos::Status;
using dcos::systemAgent;
using shell::CommandResult;

MfioBoard consoleBoard("mfio0");

// Prints a microvolt value as volts with six decimals and a sign.
void printVolts(shell::Shell& shell, int32_t microvolts)
{
    const uint32_t magnitude = microvolts < 0 ? static_cast<uint32_t>(-int64_t{microvolts})
                                              : static_cast<uint32_t>(microvolts);
    shell.print("%c%lu.%06lu V", microvolts < 0 ? '-' : '+', static_cast<unsigned long>(magnitude / 1000000u),
                static_cast<unsigned long>(magnitude % 1000000u));
}

// Parses a channel number (0-17) or name (ai0-ai7, ao0-ao7, di, do).
bool parseChannel(const char* text, uint32_t& number)
{
    if ((text[0] == 'a' || text[0] == 'A') && (text[1] == 'i' || text[1] == 'o' || text[1] == 'I' || text[1] == 'O') &&
        text[2] >= '0' && text[2] <= '7' && text[3] == '\0') {
        const bool input = text[1] == 'i' || text[1] == 'I';
        number = (input ? channel::kAnalogInput0 : channel::kAnalogOutput0) + static_cast<uint32_t>(text[2] - '0');
        return true;
    }
    if ((text[0] == 'd' || text[0] == 'D') && text[2] == '\0') {
        if (text[1] == 'i' || text[1] == 'I') {
            number = channel::kDigitalInputs;
            return true;
        }
        if (text[1] == 'o' || text[1] == 'O') {
            number = channel::kDigitalOutputs;
            return true;
        }
    }
    unsigned long value = 0;
    if (!shell::Shell::parseUnsigned(text, value) || value >= channel::kCount) {
        return false;
    }
    number = static_cast<uint32_t>(value);
    return true;
}

// Writes a channel number the way the console names it: ai3, ao0, di, do.
void printChannelName(shell::Shell& shell, uint32_t number)
{
    if (number < channel::kAnalogOutput0) {
        shell.print("ai%lu", static_cast<unsigned long>(number - channel::kAnalogInput0));
    } else if (number < channel::kDigitalInputs) {
        shell.print("ao%lu", static_cast<unsigned long>(number - channel::kAnalogOutput0));
    } else {
        shell.print(number == channel::kDigitalInputs ? "di" : "do");
    }
}

// Parses a channel argument; prints what was wrong with it and returns false.
bool parseChannelArgument(shell::Shell& shell, const char* text, uint32_t& number)
{
    if (parseChannel(text, number)) {
        return true;
    }
    shell.print("error: unknown channel '%s': the channels are ai0-ai7, ao0-ao7, di and do, or 0-%lu\r\n", text,
                static_cast<unsigned long>(channel::kCount - 1));
    return false;
}

// The subcommand's own usage line, printed after an error in its arguments
// instead of the usage of every subcommand.
CommandResult subcommandUsage(shell::Shell& shell, const char* usage)
{
    shell.print("usage: iobus %s\r\n", usage);
    return CommandResult::Failed;
}

// Parses the optional [base] [irq] at argv[first] and argv[first + 1]; prints
// what was wrong and returns false.
bool parseLocation(shell::Shell& shell, int argc, char** argv, int first, uint16_t& base, uint8_t& irq)
{
    base = consoleBoard.base();
    irq = consoleBoard.irq();
    if (argc > first + 2) {
        shell.print("error: too many arguments: give at most a base port and an interrupt line\r\n");
        return false;
    }
    unsigned long value = 0;
    if (argc > first) {
        constexpr unsigned long kHighestBase = 0xFFFFu - mfio::kWindowSize + 1u;
        if (!shell::Shell::parseUnsigned(argv[first], value) || value > kHighestBase || (value & 1u) != 0) {
            shell.print("error: base '%s' is not an even port from 0x000 to 0x%04lx\r\n", argv[first], kHighestBase);
            return false;
        }
        base = static_cast<uint16_t>(value);
    }
    if (argc > first + 1) {
        if (!shell::Shell::parseUnsigned(argv[first + 1], value) || value >= IsaResourceManager::kLineCount) {
            shell.print("error: irq '%s' is not an interrupt line from 0 to %lu\r\n", argv[first + 1],
                        static_cast<unsigned long>(IsaResourceManager::kLineCount - 1));
            return false;
        }
        irq = static_cast<uint8_t>(value);
    }
    return true;
}

// Makes the console's board sit at base and irq and be installed. Prints
// the reason and returns false when that is impossible.
bool installAt(shell::Shell& shell, uint16_t base, uint8_t irq, bool quiet = false)
{
    if (consoleBoard.installed() && (consoleBoard.base() != base || consoleBoard.irq() != irq)) {
        const Status removed = consoleBoard.uninstall();
        if (removed != Status::Ok) {
            shell.print("error: cannot move %s: %s\r\n", consoleBoard.claimant(), dcos::statusName(removed));
            return false;
        }
    }
    if (consoleBoard.installed()) {
        return true;
    }
    const Status configured = consoleBoard.configure(base, irq);
    if (configured != Status::Ok) {
        shell.print("error: cannot configure %s: %s\r\n", consoleBoard.claimant(), dcos::statusName(configured));
        return false;
    }
    consoleBoard.setDiagnosticSink(&bsp::console());
    IsaConflict conflict;
    const dcos::Result<dcos::ObjectId> installed = consoleBoard.install("mfio0", dcos::Visibility::Regional, &conflict);
    if (!installed.ok()) {
        if (installed.status() == Status::AlreadyExists) {
            char text[96];
            IsaResourceManager::describe(conflict, text, sizeof text);
            shell.print("error: %s\r\n", text);
        } else if (!quiet) {
            shell.print("error: cannot install %s: %s\r\n", consoleBoard.claimant(),
                        dcos::statusName(installed.status()));
        }
        return false;
    }
    // The console task never ends, but the device belongs to the system so
    // that no one's resource recovery takes it away.
    (void)systemAgent.XferOwnership(installed.value(), dcos::ObjectId{});
    return true;
}

// Opens the installed board; prints why not.
bool openBoard(shell::Shell& shell)
{
    const Status opened = systemAgent.Open(consoleBoard.id());
    if (opened == Status::Ok) {
        return true;
    }
    if (opened == Status::NotFound) {
        shell.print("error: no I/O board at 0x%03x: %s\r\n", consoleBoard.base(), dcos::statusName(opened));
    } else {
        shell.print("error: cannot open %s: %s\r\n", consoleBoard.claimant(), dcos::statusName(opened));
    }
    return false;
}

void closeBoard() { (void)systemAgent.Close(consoleBoard.id()); }

CommandResult probe(shell::Shell& shell, int argc, char** argv)
{
    uint16_t base;
    uint8_t irq;
    if (!parseLocation(shell, argc, argv, 2, base, irq)) {
        return subcommandUsage(shell, "probe [base] [irq]");
    }
    if (!installAt(shell, base, irq)) {
        return CommandResult::Failed;
    }
    const Status probed = systemAgent.Probe(consoleBoard.id());
    BoardInfo info{};
    // Control needs an open device; read the identity the probe stored instead.
    if (probed == Status::Ok && openBoard(shell)) {
        (void)systemAgent.Control(consoleBoard.id(), MfioBoard::kGetInfo, &info, sizeof info);
        closeBoard();
        shell.print("mfio0 at 0x%03x irq %u: present, id 0x%04x revision %u.%u\r\n", base, irq, info.id,
                    info.revision >> 8, info.revision & 0xFFu);
        return CommandResult::Ok;
    }
    shell.print("mfio0 at 0x%03x irq %u: absent (%s)\r\n", base, irq, dcos::statusName(probed));
    return CommandResult::Failed;
}

void printReading(shell::Shell& shell, uint32_t number, uint16_t word)
{
    if (number < channel::kAnalogOutput0) {
        GainSetting setting{number, 1};
        (void)systemAgent.Control(consoleBoard.id(), MfioBoard::kGetGain, &setting, sizeof setting);
        const AnalogValue value = AnalogScaling::adcToMicrovolts(word, AnalogScaling::fromFactor(setting.gain).value());
        shell.print("ai%lu code=%u gain=%lu value=", static_cast<unsigned long>(number),
                    static_cast<unsigned>(word & mfio::kAdcDataCodeMask), static_cast<unsigned long>(setting.gain));
        printVolts(shell, value.microvolts);
        shell.print(" overrange=%u\r\n", value.overrange ? 1u : 0u);
    } else if (number < channel::kDigitalInputs) {
        shell.print("ao%lu code=%u value=", static_cast<unsigned long>(number - channel::kAnalogOutput0), word);
        printVolts(shell, AnalogScaling::dacToMicrovolts(word));
        shell.print("\r\n");
    } else {
        shell.print("%s=0x%04x\r\n", number == channel::kDigitalInputs ? "di" : "do", word);
    }
}

CommandResult read(shell::Shell& shell, int argc, char** argv)
{
    uint32_t number;
    if (argc != 3) {
        shell.print("error: read takes one channel\r\n");
        return subcommandUsage(shell, "read <channel>");
    }
    if (!parseChannelArgument(shell, argv[2], number)) {
        return CommandResult::Failed;
    }
    if (!installAt(shell, consoleBoard.base(), consoleBoard.irq()) || !openBoard(shell)) {
        return CommandResult::Failed;
    }
    const dcos::Result<uint16_t> word =
        number < channel::kAnalogOutput0 ? readAnalogInput(consoleBoard.id(), number) : readWord(consoleBoard.id(), number);
    if (word.ok()) {
        printReading(shell, number, word.value());
    } else {
        shell.print("error: cannot read channel %lu: %s\r\n", static_cast<unsigned long>(number),
                    dcos::statusName(word.status()));
    }
    closeBoard();
    return word.ok() ? CommandResult::Ok : CommandResult::Failed;
}

CommandResult write(shell::Shell& shell, int argc, char** argv)
{
    uint32_t number;
    unsigned long value = 0;
    if (argc != 4) {
        shell.print("error: write takes a channel and a value\r\n");
        return subcommandUsage(shell, "write <channel> <value>");
    }
    if (!parseChannelArgument(shell, argv[2], number)) {
        return CommandResult::Failed;
    }
    if (number < channel::kAnalogOutput0 || number == channel::kDigitalInputs) {
        shell.print("error: ");
        printChannelName(shell, number);
        shell.print(" is an input; write takes an analog output ao0-ao7 or do\r\n");
        return CommandResult::Failed;
    }
    const unsigned long largest = number == channel::kDigitalOutputs ? 0xFFFFu : mfio::kCodeMaximum;
    if (!shell::Shell::parseUnsigned(argv[3], value) || value > largest) {
        shell.print("error: value '%s' is out of range for ", argv[3]);
        printChannelName(shell, number);
        shell.print(": 0 to %lu (0x%lx)\r\n", largest, largest);
        return CommandResult::Failed;
    }
    if (!installAt(shell, consoleBoard.base(), consoleBoard.irq()) || !openBoard(shell)) {
        return CommandResult::Failed;
    }
    const Status written = writeWord(consoleBoard.id(), number, static_cast<uint16_t>(value));
    if (written == Status::Ok) {
        printReading(shell, number, static_cast<uint16_t>(value));
    } else {
        shell.print("error: cannot write channel %lu: %s\r\n", static_cast<unsigned long>(number),
                    dcos::statusName(written));
    }
    closeBoard();
    return written == Status::Ok ? CommandResult::Ok : CommandResult::Failed;
}

CommandResult gain(shell::Shell& shell, int argc, char** argv)
{
    uint32_t number;
    unsigned long factor = 0;
    if (argc != 4) {
        shell.print("error: gain takes an analog input and a factor\r\n");
        return subcommandUsage(shell, "gain <channel> <1|10|100|1000>");
    }
    if (!parseChannelArgument(shell, argv[2], number)) {
        return CommandResult::Failed;
    }
    if (number >= channel::kAnalogOutput0) {
        shell.print("error: ");
        printChannelName(shell, number);
        shell.print(" has no gain; the programmable gain is on the analog inputs ai0-ai7\r\n");
        return CommandResult::Failed;
    }
    if (!shell::Shell::parseUnsigned(argv[3], factor) || !AnalogScaling::fromFactor(factor).ok()) {
        shell.print("error: gain '%s' is not one of 1, 10, 100 and 1000\r\n", argv[3]);
        return CommandResult::Failed;
    }
    if (!installAt(shell, consoleBoard.base(), consoleBoard.irq()) || !openBoard(shell)) {
        return CommandResult::Failed;
    }
    const Status set = setGain(consoleBoard.id(), number, static_cast<uint32_t>(factor));
    if (set == Status::Ok) {
        shell.print("ai%lu gain=%lu\r\n", static_cast<unsigned long>(number), factor);
    } else {
        shell.print("error: cannot set the gain: %s\r\n", dcos::statusName(set));
    }
    closeBoard();
    return set == Status::Ok ? CommandResult::Ok : CommandResult::Failed;
}

CommandResult bringup(shell::Shell& shell, int argc, char** argv)
{
    uint16_t base;
    uint8_t irq;
    if (!parseLocation(shell, argc, argv, 2, base, irq)) {
        return subcommandUsage(shell, "bringup [base] [irq]");
    }
    shell.print("BRINGUP BEGIN base=0x%03x irq=%u\r\n", base, irq);
    if (!installAt(shell, base, irq)) {
        shell.print("BRINGUP END failures=1\r\n");
        return CommandResult::Failed;
    }
    const Status probed = systemAgent.Probe(consoleBoard.id());
    if (probed != Status::Ok || systemAgent.Open(consoleBoard.id()) != Status::Ok) {
        shell.print("BRINGUP PROBE absent\r\nBRINGUP END failures=1\r\n");
        return CommandResult::Failed;
    }
    BoardInfo info{};
    (void)systemAgent.Control(consoleBoard.id(), MfioBoard::kGetInfo, &info, sizeof info);
    shell.print("BRINGUP PROBE ok id=%04x revision=%04x\r\n", info.id, info.revision);
    const unsigned failures = runBringupSteps(shell.output(), consoleBoard.id(), BringupSettings{});
    closeBoard();
    shell.print("BRINGUP END failures=%u\r\n", failures);
    return failures == 0 ? CommandResult::Ok : CommandResult::Failed;
}

CommandResult resources(shell::Shell& shell, int argc, char**)
{
    if (argc != 2) {
        shell.print("error: resources takes no arguments\r\n");
        return subcommandUsage(shell, "resources");
    }
    IsaResourceManager& manager = isaResources();
    shell.print("claimant         ports        irq\r\n");
    IsaReservation entry;
    for (size_t i = 0; manager.entry(i, entry); ++i) {
        shell.print("%-15s  ", entry.claimant);
        if (entry.hasPorts) {
            shell.print("0x%03x-0x%03x  ", entry.ports.first, entry.ports.last);
        } else {
            shell.print("-            ");
        }
        if (entry.line != kNoIrq) {
            shell.print("%u\r\n", static_cast<unsigned>(entry.line));
        } else {
            shell.print("-\r\n");
        }
    }
    return CommandResult::Ok;
}

CommandResult statistics(shell::Shell& shell, int argc, char**)
{
    if (argc != 2) {
        shell.print("error: stats takes no arguments\r\n");
        return subcommandUsage(shell, "stats");
    }
    if (!consoleBoard.installed()) {
        shell.print("mfio0 is not installed\r\n");
        return CommandResult::Failed;
    }
    if (!openBoard(shell)) {
        return CommandResult::Failed;
    }
    BoardStatistics s{};
    uint32_t mode = 0;
    (void)systemAgent.Control(consoleBoard.id(), MfioBoard::kGetStatistics, &s, sizeof s);
    (void)systemAgent.Control(consoleBoard.id(), MfioBoard::kGetMode, &mode, sizeof mode);
    closeBoard();
    shell.print("mode=%s conversions=%lu interrupts=%lu spurious=%lu missed=%lu fallbacks=%lu overranges=%lu "
                "timeouts=%lu\r\n",
                mode == static_cast<uint32_t>(ConversionMode::Polled) ? "polled" : "interrupt",
                static_cast<unsigned long>(s.conversions), static_cast<unsigned long>(s.interrupts),
                static_cast<unsigned long>(s.spuriousInterrupts), static_cast<unsigned long>(s.missedInterrupts),
                static_cast<unsigned long>(s.fallbacks), static_cast<unsigned long>(s.overranges),
                static_cast<unsigned long>(s.timeouts));
    return CommandResult::Ok;
}

constexpr shell::Subcommand kSubcommands[] = {
    {"probe", probe},         {"read", read},       {"write", write},           {"gain", gain},
    {"bringup", bringup},     {"resources", resources}, {"stats", statistics},
};

CommandResult iobus(shell::Shell& shell, int argc, char** argv)
{
    return shell::runSubcommand(shell, argc, argv, kSubcommands);
}

} // namespace

DCOS_SHELL_COMMAND(iobusCommand, "iobus", "probe, read, write and bring up the multi-function I/O board",
                   "iobus probe [base] [irq] | read <channel> | write <channel> <value> | "
                   "gain <channel> <1|10|100|1000> | bringup [base] [irq] | resources | stats",
                   iobus);

} // namespace iobus
