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
    EXPECT_EQ(feedAll(editor, "a\x01" "b\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "ab");
}

// The defect: the arrow keys' escape sequences were run as commands
// ("unknown command '[A'").
TEST(LineEditor, ArrowKeysAreNeverText)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    EXPECT_EQ(feedAll(editor, "\x1b[A\x1b[B\x1b[C\x1b[D\x1bOA\x1bOD\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "");
    EXPECT_EQ(echo.text.find('['), std::string::npos);
    EXPECT_EQ(echo.text.find('A'), std::string::npos);
}

TEST(LineEditor, UnknownSequencesAreSwallowedWhole)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    // F5, Ctrl-Right, a bracketed-paste marker, Alt-x, and F1 in SS3 form.
    EXPECT_EQ(feedAll(editor, "x\x1b[15~\x1b[1;5C\x1b[200~\x1bx\x1bOPy\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "xy");
    EXPECT_EQ(echo.text, "xy\r\n");
}

TEST(LineEditor, AnOverlongSequenceIsDroppedWithoutEchoOrEffect)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    std::string keys = "ok\x1b[";
    keys += std::string(100, '9');
    keys += "A\r";
    EXPECT_EQ(feedAll(editor, keys), Event::LineReady);
    EXPECT_STREQ(editor.line(), "ok");
}

TEST(LineEditor, UpAndDownWalkTheHistoryAndComeBackToTheDraft)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    feedAll(editor, "tasks\r");
    feedAll(editor, "mem\r");
    feedAll(editor, "mem\r"); // A repeat is kept once.
    EXPECT_EQ(editor.historySize(), 2u);
    feedAll(editor, "ver");
    feedAll(editor, "\x1b[A");
    EXPECT_EQ(std::string(editor.line(), editor.length()), "mem");
    feedAll(editor, "\x1b[A");
    EXPECT_EQ(std::string(editor.line(), editor.length()), "tasks");
    feedAll(editor, "\x1b[A"); // Past the oldest: stays.
    EXPECT_EQ(std::string(editor.line(), editor.length()), "tasks");
    feedAll(editor, "\x1b[B\x1b[B");
    EXPECT_EQ(std::string(editor.line(), editor.length()), "ver") << "the line being typed comes back";
    EXPECT_EQ(feedAll(editor, "sion\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "version");
    // Recalled and run again.
    EXPECT_EQ(feedAll(editor, "\x1b[A\x1b[A\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "mem");
}

TEST(LineEditor, TheHistoryKeepsTheNewestLines)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    for (int i = 0; i < 20; ++i) {
        feedAll(editor, "echo " + std::to_string(i) + "\r");
    }
    EXPECT_EQ(editor.historySize(), shell::LineEditor::kHistoryDepth);
    for (size_t i = 0; i < shell::LineEditor::kHistoryDepth + 3; ++i) {
        feedAll(editor, "\x1b[A");
    }
    EXPECT_EQ(std::string(editor.line(), editor.length()), "echo 12");
}

TEST(LineEditor, RecallingAShorterLineBlanksTheRestOfTheLongerOne)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    feedAll(editor, "ls\r");
    echo.text.clear();
    feedAll(editor, "longer");
    feedAll(editor, "\x1b[A");
    // Six BS to the start, "ls", four blanks over "nger", four BS back.
    EXPECT_EQ(echo.text, "longer" + std::string(6, '\b') + "ls    " + std::string(4, '\b'));
}

TEST(LineEditor, LeftRightHomeEndAndDeleteEditInsideTheLine)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    feedAll(editor, "ecoh");
    feedAll(editor, "\x1b[D\x1b[D"); // Cursor before "oh".
    EXPECT_EQ(editor.cursor(), 2u);
    feedAll(editor, "\x1b[3~");        // Delete the "o".
    feedAll(editor, "\x1b[C");         // After the "h".
    EXPECT_EQ(feedAll(editor, "o\x1b[H\x1b[3~E\x1b[F!\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "Echo!");
}

TEST(LineEditor, InsertingInTheMiddleRedrawsTheRest)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    feedAll(editor, "hllo\x1b[D\x1b[D\x1b[D");
    echo.text.clear();
    feedAll(editor, "e");
    EXPECT_EQ(echo.text, "ello\b\b\b");
    EXPECT_EQ(feedAll(editor, "\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "hello");
}

TEST(LineEditor, BackspaceInTheMiddleClosesTheGap)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    EXPECT_EQ(feedAll(editor, "helxlo\x1b[D\x1b[D\b\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "hello");
}

TEST(LineEditor, ABrokenSequenceGivesItsCharacterBack)
{
    StringSink echo;
    shell::LineEditor editor(echo);
    // ESC [ then a line end: the sequence is abandoned and the line ends.
    EXPECT_EQ(feedAll(editor, "ab\x1b[\r"), Event::LineReady);
    EXPECT_STREQ(editor.line(), "ab");
}

} // namespace
