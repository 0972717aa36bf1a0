#include <shell/Shell.hpp>

#include "StringSink.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

int lastArgc = 0;
std::string lastArguments;

shell::CommandResult recordArguments(shell::Shell&, int argc, char** argv)
{
    lastArgc = argc;
    lastArguments.clear();
    for (int i = 0; i < argc; ++i) {
        lastArguments += std::string(argv[i]) + "|";
    }
    return argc > 3 ? shell::CommandResult::UsageError : shell::CommandResult::Ok;
}

DCOS_SHELL_COMMAND(recordCommand, "record", "records its arguments (host test)", "record [a] [b]",
                   recordArguments);

void typeLine(shell::Shell& shell, const std::string& text)
{
    for (char c : text) {
        shell.feed(c);
    }
}

TEST(CommandTable, FindsCommandsRegisteredInAnyFile)
{
    EXPECT_NE(shell::CommandTable::find("record"), nullptr);
    EXPECT_NE(shell::CommandTable::find("help"), nullptr);
    EXPECT_NE(shell::CommandTable::find("echo"), nullptr);
    EXPECT_EQ(shell::CommandTable::find("nonesuch"), nullptr);
    EXPECT_EQ(shell::CommandTable::find("rec"), nullptr);
    EXPECT_GE(shell::CommandTable::size(), 3u);
}

TEST(Shell, SplitsWordsOnSpacesAndTabs)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    char line[] = "  record  one\ttwo ";
    EXPECT_EQ(shell.execute(line), shell::CommandResult::Ok);
    EXPECT_EQ(lastArgc, 3);
    EXPECT_EQ(lastArguments, "record|one|two|");
}

TEST(Shell, BadArgumentsPrintTheUsageLine)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    char line[] = "record 1 2 3";
    EXPECT_EQ(shell.execute(line), shell::CommandResult::UsageError);
    EXPECT_EQ(out.text, "usage: record [a] [b]\r\n");
}

TEST(Shell, UnknownCommandIsNamed)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    char line[] = "frobnicate now";
    EXPECT_EQ(shell.execute(line), shell::CommandResult::Failed);
    EXPECT_EQ(out.text, "error: unknown command 'frobnicate'; type 'help' for the list\r\n");
}

TEST(Shell, TooManyWordsIsAnError)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    std::string text = "record";
    for (int i = 0; i < shell::Shell::maximumArguments; ++i) {
        text += " x";
    }
    EXPECT_EQ(shell.execute(text.data()), shell::CommandResult::Failed);
    EXPECT_NE(out.text.find("too many arguments"), std::string::npos);
}

TEST(Shell, EmptyLineJustPromptsAgain)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    typeLine(shell, "\r");
    EXPECT_EQ(out.text, "\r\n> ");
}

TEST(Shell, TypedLineRunsAndPromptsAgain)
{
    StringSink out;
    shell::Shell shell(out, "dcos> ");
    shell.start();
    typeLine(shell, "echo hello   world\r");
    EXPECT_EQ(out.text, "dcos> echo hello   world\r\nhello world\r\ndcos> ");
}

TEST(Shell, OverlongLineIsRefusedWithAClearError)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    lastArgc = 0;
    typeLine(shell, "record " + std::string(400, 'z') + "\r");
    EXPECT_EQ(lastArgc, 0);
    EXPECT_NE(out.text.find("error: line too long (at most 255 characters); nothing was run"), std::string::npos);
}

TEST(Shell, HelpListsEveryCommandAlphabetically)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    char line[] = "help";
    EXPECT_EQ(shell.execute(line), shell::CommandResult::Ok);
    const size_t echoAt = out.text.find("  echo ");
    const size_t helpAt = out.text.find("  help ");
    const size_t recordAt = out.text.find("  record ");
    ASSERT_NE(echoAt, std::string::npos);
    ASSERT_NE(helpAt, std::string::npos);
    ASSERT_NE(recordAt, std::string::npos);
    EXPECT_LT(echoAt, helpAt);
    EXPECT_LT(helpAt, recordAt);
}

TEST(Shell, HelpForOneCommandShowsItsUsage)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    char line[] = "help record";
    EXPECT_EQ(shell.execute(line), shell::CommandResult::Ok);
    EXPECT_EQ(out.text, "record - records its arguments (host test)\r\nusage: record [a] [b]\r\n");
    out.take();
    char unknown[] = "help nonesuch";
    EXPECT_EQ(shell.execute(unknown), shell::CommandResult::Failed);
    EXPECT_EQ(out.text, "error: unknown command 'nonesuch'\r\n");
}

TEST(Shell, ParseUnsignedAcceptsDecimalAndHexOnly)
{
    unsigned long value = 0;
    EXPECT_TRUE(shell::Shell::parseUnsigned("1234", value));
    EXPECT_EQ(value, 1234u);
    EXPECT_TRUE(shell::Shell::parseUnsigned("0x3F8", value));
    EXPECT_EQ(value, 0x3F8u);
    EXPECT_TRUE(shell::Shell::parseUnsigned("4294967295", value));
    EXPECT_EQ(value, 4294967295u);
    EXPECT_FALSE(shell::Shell::parseUnsigned("4294967296", value));
    EXPECT_FALSE(shell::Shell::parseUnsigned("", value));
    EXPECT_FALSE(shell::Shell::parseUnsigned("0x", value));
    EXPECT_FALSE(shell::Shell::parseUnsigned("12a", value));
    EXPECT_FALSE(shell::Shell::parseUnsigned("-1", value));
}

} // namespace

namespace {

shell::CommandResult firstSubcommand(shell::Shell& shell, int, char**)
{
    shell.print("first\r\n");
    return shell::CommandResult::Ok;
}

shell::CommandResult secondSubcommand(shell::Shell& shell, int argc, char** argv)
{
    shell.print("second %d %s\r\n", argc, argv[1]);
    return shell::CommandResult::Failed;
}

constexpr shell::Subcommand kTestSubcommands[] = {{"first", firstSubcommand}, {"second", secondSubcommand}};

TEST(Subcommands, RunTheNamedOneAndNameAnUnknownOneWithTheList)
{
    StringSink out;
    shell::Shell shell(out, "> ");
    char first[] = "first";
    char second[] = "second";
    char fir[] = "fir";
    char firstly[] = "firstly";
    char command[] = "cmd";
    char* argv[] = {command, first, nullptr};
    EXPECT_EQ(shell::runSubcommand(shell, 2, argv, kTestSubcommands), shell::CommandResult::Ok);
    EXPECT_EQ(out.take(), "first\r\n");
    argv[1] = second;
    EXPECT_EQ(shell::runSubcommand(shell, 2, argv, kTestSubcommands), shell::CommandResult::Failed);
    EXPECT_EQ(out.take(), "second 2 second\r\n");
    for (char* unknown : {fir, firstly}) {
        argv[1] = unknown;
        EXPECT_EQ(shell::runSubcommand(shell, 2, argv, kTestSubcommands), shell::CommandResult::Failed);
        EXPECT_EQ(out.take(), "error: unknown subcommand '" + std::string(unknown) +
                                  "': the subcommands are first second\r\n");
    }
    EXPECT_EQ(shell::runSubcommand(shell, 1, argv, kTestSubcommands), shell::CommandResult::UsageError);
    EXPECT_EQ(out.take(), "");
}

} // namespace
