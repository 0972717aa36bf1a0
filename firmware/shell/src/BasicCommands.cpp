// Commands every image has, help and echo, and the subcommand dispatch
// commands with several subcommands share.
#include <shell/Shell.hpp>

namespace shell {

namespace {

bool alphabeticallyBefore(const char* a, const char* b)
{
    while (*a != '\0' && *a == *b) {
        ++a;
        ++b;
    }
    return static_cast<unsigned char>(*a) < static_cast<unsigned char>(*b);
}

CommandResult help(Shell& shell, int argc, char** argv)
{
    if (argc > 2) {
        return CommandResult::UsageError;
    }
    if (argc == 2) {
        const ShellCommand* command = CommandTable::find(argv[1]);
        if (command == nullptr) {
            shell.print("error: unknown command '%s'\r\n", argv[1]);
            return CommandResult::Failed;
        }
        shell.print("%s - %s\r\nusage: %s\r\n", command->name, command->summary, command->usage);
        if (command->details != nullptr) {
            shell.print("%s\r\n", command->details);
        }
        return CommandResult::Ok;
    }
    // List alphabetically. The table is in link order and small, so a
    // selection pass per line needs no buffer and no sorting of the table.
    const ShellCommand* previous = nullptr;
    for (size_t listed = 0; listed < CommandTable::size(); ++listed) {
        const ShellCommand* next = nullptr;
        for (const ShellCommand* c = CommandTable::begin(); c != CommandTable::end(); ++c) {
            const bool afterPrevious = previous == nullptr || alphabeticallyBefore(previous->name, c->name);
            if (afterPrevious && (next == nullptr || alphabeticallyBefore(c->name, next->name))) {
                next = c;
            }
        }
        if (next == nullptr) {
            break;
        }
        shell.print("  %-10s %s\r\n", next->name, next->summary);
        previous = next;
    }
    return CommandResult::Ok;
}

CommandResult echo(Shell& shell, int argc, char** argv)
{
    for (int i = 1; i < argc; ++i) {
        shell.print(i == 1 ? "%s" : " %s", argv[i]);
    }
    shell.print("\r\n");
    return CommandResult::Ok;
}

} // namespace

CommandResult runSubcommand(Shell& shell, int argc, char** argv, const Subcommand* table, size_t count)
{
    if (argc < 2) {
        return CommandResult::UsageError;
    }
    for (size_t i = 0; i < count; ++i) {
        const char* a = argv[1];
        const char* b = table[i].name;
        while (*a != '\0' && *a == *b) {
            ++a;
            ++b;
        }
        if (*a == *b) {
            return table[i].run(shell, argc, argv);
        }
    }
    shell.print("error: unknown subcommand '%s': the subcommands are", argv[1]);
    for (size_t i = 0; i < count; ++i) {
        shell.print(" %s", table[i].name);
    }
    shell.print("\r\n");
    return CommandResult::Failed;
}

DCOS_SHELL_COMMAND(helpCommand, "help", "list commands, or show one command's usage", "help [command]", help);
DCOS_SHELL_COMMAND(echoCommand, "echo", "print the arguments", "echo [text...]", echo);

} // namespace shell
