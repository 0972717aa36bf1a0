// The controller's console command interpreter.
//
// The shell reads characters through a LineEditor, splits a finished line
// into words, and runs the matching command from the CommandTable. It never
// allocates: the words point into the editor's line buffer.
#pragma once

#include <stdarg.h>
#include <stddef.h>

#include <runtime/Format.hpp>
#include <shell/LineEditor.hpp>
#include <shell/ShellCommand.hpp>

namespace shell {

class Shell {
public:
    /// The most words a command line may have, command name included.
    static constexpr int maximumArguments = 16;

    Shell(runtime::CharacterSink& output, const char* prompt);

    /// Prints the prompt; call once when the console is ready.
    void start();

    /// Feeds one received character; runs a command when a line completes.
    void feed(char character);

    /// Runs one complete line as if typed (used by feed() and by tests).
    /// Returns the command's result, or Failed for an unknown command.
    CommandResult execute(char* line);

    /// Formatted output on the console.
    void print(const char* format, ...) __attribute__((format(printf, 2, 3)));

    runtime::CharacterSink& output() { return output_; }

    /// Parses a decimal or 0x-prefixed hexadecimal unsigned number that
    /// must fit in 32 bits. Returns false for anything else.
    static bool parseUnsigned(const char* text, unsigned long& value);

private:
    runtime::CharacterSink& output_;
    const char* prompt_;
    LineEditor editor_;
};

} // namespace shell
