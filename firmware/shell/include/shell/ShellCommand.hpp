// Registration of console commands.
//
// A module adds a command by defining one DCOS_SHELL_COMMAND in its own
// source file. The linker gathers every definition into one table (the
// section dcos_shell_commands), so the shell has no central list or switch
// to edit, and a module left out of an image takes its commands with it.
#pragma once

#include <stddef.h>

namespace shell {

class Shell;

/// What a command reports back to the shell.
enum class CommandResult {
    Ok,         ///< Done.
    Failed,     ///< Done, with an error the command has already printed.
    UsageError, ///< The arguments were wrong; the shell prints the usage line.
};

struct ShellCommand {
    /// The word that invokes the command.
    const char* name;
    /// One line for 'help'.
    const char* summary;
    /// The argument synopsis, e.g. "echo [text...]".
    const char* usage;
    /// Runs the command; argv[0] is the command name.
    CommandResult (*run)(Shell& shell, int argc, char** argv);
    /// What 'help <command>' adds after the usage line: what the columns
    /// and flags of a listing mean. nullptr when the summary says it all.
    const char* details = nullptr;
};

/// One subcommand of a command that has several (`iobus read`, `can up`).
struct Subcommand {
    const char* name;
    /// Runs the subcommand; argv[0] is the command, argv[1] the subcommand.
    CommandResult (*run)(Shell& shell, int argc, char** argv);
};

/// Runs the subcommand argv[1] names from @p table (@p count entries). With
/// no subcommand it is a usage error; an unknown one is named, with the list.
CommandResult runSubcommand(Shell& shell, int argc, char** argv, const Subcommand* table, size_t count);

/// The same for a table array.
template <size_t Count>
CommandResult runSubcommand(Shell& shell, int argc, char** argv, const Subcommand (&table)[Count])
{
    return runSubcommand(shell, argc, argv, table, Count);
}

/// The commands linked into this image, in link order.
class CommandTable {
public:
    static const ShellCommand* begin();
    static const ShellCommand* end();
    static size_t size() { return static_cast<size_t>(end() - begin()); }
    /// The command called name, or nullptr.
    static const ShellCommand* find(const char* name);
};

} // namespace shell

/// Defines a console command. Use once per command at namespace scope.
#define DCOS_SHELL_COMMAND(identifier, name, summary, usage, function) \
    DCOS_SHELL_COMMAND_DETAILED(identifier, name, summary, usage, nullptr, function)

/// Defines a console command whose 'help' also explains its output: details
/// is printed after the usage line, one explanation per line ("\r\n" apart).
///
/// The section is read as one array, so every entry must sit exactly
/// sizeof(ShellCommand) after the previous one: the explicit alignment stops
/// the compiler from aligning larger objects further (GCC gives objects of
/// 32 bytes or more 32-byte alignment on x86-64), which would leave gaps.
#define DCOS_SHELL_COMMAND_DETAILED(identifier, name, summary, usage, details, function)        \
    [[gnu::used, gnu::section("dcos_shell_commands"), gnu::aligned(alignof(::shell::ShellCommand))]] \
    constinit const ::shell::ShellCommand identifier{name, summary, usage, function, details}
