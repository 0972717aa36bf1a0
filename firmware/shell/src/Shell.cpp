#include <shell/Shell.hpp>

#include <runtime/Text.hpp>

namespace shell {

extern "C" {
// Provided by the linker: the bounds of the dcos_shell_commands section.
extern const ShellCommand __start_dcos_shell_commands[];
extern const ShellCommand __stop_dcos_shell_commands[];
}

const ShellCommand* CommandTable::begin() { return __start_dcos_shell_commands; }

const ShellCommand* CommandTable::end() { return __stop_dcos_shell_commands; }

const ShellCommand* CommandTable::find(const char* name)
{
    for (const ShellCommand* command = begin(); command != end(); ++command) {
        if (runtime::textEquals(command->name, name)) {
            return command;
        }
    }
    return nullptr;
}

Shell::Shell(runtime::CharacterSink& output, const char* prompt)
    : output_(output), prompt_(prompt), editor_(output)
{
}

void Shell::start() { print("%s", prompt_); }

void Shell::print(const char* format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    runtime::formatTo(output_, format, arguments);
    va_end(arguments);
}

bool Shell::parseUnsigned(const char* text, unsigned long& value)
{
    unsigned base = 10;
    if (text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
        base = 16;
        text += 2;
    }
    if (*text == '\0') {
        return false;
    }
    unsigned long long result = 0;
    for (; *text != '\0'; ++text) {
        unsigned digit;
        if (*text >= '0' && *text <= '9') {
            digit = static_cast<unsigned>(*text - '0');
        } else if (base == 16 && *text >= 'a' && *text <= 'f') {
            digit = static_cast<unsigned>(*text - 'a' + 10);
        } else if (base == 16 && *text >= 'A' && *text <= 'F') {
            digit = static_cast<unsigned>(*text - 'A' + 10);
        } else {
            return false;
        }
        if (digit >= base) {
            return false;
        }
        result = result * base + digit;
        if (result > 0xFFFFFFFFull) {
            return false;
        }
    }
    value = static_cast<unsigned long>(result);
    return true;
}

CommandResult Shell::execute(char* line)
{
    char* argv[maximumArguments + 1];
    int argc = 0;
    char* p = line;
    for (;;) {
        while (*p == ' ' || *p == '\t') {
            *p++ = '\0';
        }
        if (*p == '\0') {
            break;
        }
        if (argc == maximumArguments) {
            print("error: too many arguments (at most %d words)\r\n", maximumArguments);
            return CommandResult::Failed;
        }
        argv[argc++] = p;
        while (*p != '\0' && *p != ' ' && *p != '\t') {
            ++p;
        }
    }
    argv[argc] = nullptr;
    if (argc == 0) {
        return CommandResult::Ok;
    }
    const ShellCommand* command = CommandTable::find(argv[0]);
    if (command == nullptr) {
        print("error: unknown command '%s'; type 'help' for the list\r\n", argv[0]);
        return CommandResult::Failed;
    }
    const CommandResult result = command->run(*this, argc, argv);
    if (result == CommandResult::UsageError) {
        print("usage: %s\r\n", command->usage);
    }
    return result;
}

void Shell::feed(char character)
{
    switch (editor_.feed(character)) {
    case LineEditor::Event::None:
        return;
    case LineEditor::Event::LineReady:
        execute(editor_.line());
        break;
    case LineEditor::Event::LineTooLong:
        print("error: line too long (at most %u characters); nothing was run\r\n",
              static_cast<unsigned>(LineEditor::maximumLineLength));
        break;
    case LineEditor::Event::Cancelled:
        break;
    }
    print("%s", prompt_);
}

} // namespace shell
