#include <shell/LineEditor.hpp>

#include "StringSink.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

using Event = shell::LineEditor::Event;

Event feedAll(shell::LineEditor& editor, const std::string& keys)
{
    Event last = Event::None;
    for (char c : keys) {
        last = editor.feed(c);
    }
    return last;
}

TEST(LineEditor, CollectsAndEchoesALine)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    EXPECT_EQ(feedAll(editor, "help\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "help");
    EXPECT_EQ(echo.text, "help\r\n");
}

TEST(LineEditor, BackspaceAndDeleteEraseTheLastCharacter)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    EXPECT_EQ(feedAll(editor, "ecgo\b\x7fho\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "echo");
    EXPECT_EQ(echo.text, "ecgo\b \b\b \bho\r\n");
}

TEST(LineEditor, BackspaceOnEmptyLineDoesNothing)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    EXPECT_EQ(feedAll(editor, "\b\bx\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "x");
    EXPECT_EQ(echo.text, "x\r\n");
}

TEST(LineEditor, CarriageReturnLineFeedIsOneLineEnd)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    EXPECT_EQ(feedAll(editor, "a\r"), Event::LineReady);
    EXPECT_EQ(editor.feed('\n'), Event::None);
    EXPECT_EQ(feedAll(editor, "b\n"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "b");
    EXPECT_EQ(editor.feed('\n'), Event::LineReady); // A second LF is an empty line.
    EXPECT_STREQ(editor.line(), "");
}

TEST(LineEditor, ControlUErasesAndControlCCancels)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    feedAll(editor, "abc\x15");
    EXPECT_EQ(echo.take(), "abc\b \b\b \b\b \b");
    EXPECT_EQ(feedAll(editor, "xy\x03"), Event::Cancelled);
    EXPECT_EQ(echo.take(), "xy^C\r\n");
    EXPECT_EQ(feedAll(editor, "z\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "z");
}

TEST(LineEditor, LongestLineIsAccepted)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    const std::string longest(shell::LineEditor::maximumLineLength, 'a');
    EXPECT_EQ(feedAll(editor, longest + "\r"), Event::LineReady);
    EXPECT_EQ(std::string(editor.line()), longest);
}

TEST(LineEditor, OverlongLineIsReportedAndNotExecuted)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    const std::string tooLong(shell::LineEditor::maximumLineLength + 50, 'b');
    EXPECT_EQ(feedAll(editor, tooLong + "\r"), Event::LineTooLong);
    EXPECT_EQ(editor.length(), 0u);
    // The echo stops where storing stopped, so the operator sees the cut.
    EXPECT_EQ(echo.take(), std::string(shell::LineEditor::maximumLineLength, 'b') + "\r\n");
    // The editor recovers for the next line.
    EXPECT_EQ(feedAll(editor, "ok\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "ok");
}

TEST(LineEditor, OtherControlCharactersAreIgnored)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    EXPECT_EQ(feedAll(editor, "a\x01\x1b" "b\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "ab");
}

} // namespace
