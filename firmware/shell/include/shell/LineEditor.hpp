// Turns a stream of terminal key presses into complete command lines.
//
// The editor echoes what it accepts, so the operator sees exactly what the
// controller will execute. It understands backspace (BS or DEL), Ctrl-U
// (erase the line), Ctrl-C (abandon the line) and CR, LF or CR LF as the
// end of a line. A line longer than the buffer is not cut silently: the
// editor stops storing, keeps reading to the end of the line, and reports
// the line as too long so nothing half-typed is executed.
//
// Terminals send the cursor keys as escape sequences (ECMA-48: CSI, "ESC [",
// parameters and a final byte; or SS3, "ESC O" and one byte). The editor
// reads every such sequence whole: Left and Right move the cursor, Home and
// End jump to the ends, Delete removes the character under the cursor, Up
// and Down walk a history of the last kHistoryDepth lines. Any other
// sequence (function keys, a modified arrow) is swallowed, never taken as
// text. The screen is redrawn with BS and spaces only, which every terminal
// understands.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <runtime/Format.hpp>

namespace shell {

class LineEditor {
public:
    /// The longest line accepted, in characters.
    static constexpr size_t maximumLineLength = 255;
    /// Lines the history keeps, newest first out.
    static constexpr size_t kHistoryDepth = 8;
    /// The longest escape sequence read; a longer one is dropped whole.
    static constexpr size_t kMaximumSequenceLength = 16;

    enum class Event {
        None,        ///< Still collecting the line.
        LineReady,   ///< line() holds a complete line.
        LineTooLong, ///< The line exceeded maximumLineLength and was discarded.
        Cancelled,   ///< Ctrl-C abandoned the line.
    };

    explicit LineEditor(runtime::CharacterSink& echo) : echo_(echo) {}

    /// Processes one received character.
    Event feed(char character);

    /// The completed line, terminated; valid after LineReady until the next feed().
    char* line() { return buffer_; }
    size_t length() const { return length_; }
    /// Where the next character typed goes, 0..length().
    size_t cursor() const { return cursor_; }
    /// Lines in the history.
    size_t historySize() const { return historyCount_; }

private:
    enum class EscapeState : uint8_t { None, Escape, ControlSequence, SingleShift };

    Event feedText(char character);
    Event handleEscape(char character);
    void runSequence(char final);
    void erase(size_t count);
    Event finish();

    void moveLeft(size_t count);
    void moveRight(size_t count);
    void insert(char character);
    void deleteUnderCursor();
    void deleteBeforeCursor();
    /// Replaces the line on screen and in the buffer with text.
    void replaceLine(const char* text);
    void remember();
    void recall(int direction);

    runtime::CharacterSink& echo_;
    char buffer_[maximumLineLength + 1] = {};
    size_t length_ = 0;
    size_t cursor_ = 0;
    bool overflowed_ = false;
    bool lastWasCarriageReturn_ = false;
    bool lineDelivered_ = false;

    EscapeState escape_ = EscapeState::None;
    char sequence_[kMaximumSequenceLength] = {};
    size_t sequenceLength_ = 0;
    bool sequenceTooLong_ = false;

    // The history: a ring of the last lines, and while the operator walks
    // it, the line being typed before the walk began (restored past the
    // newest entry).
    char history_[kHistoryDepth][maximumLineLength + 1] = {};
    size_t historyCount_ = 0;
    size_t historyNewest_ = 0;
    size_t browsing_ = 0; ///< 0: editing the draft; n: showing the n-th newest entry.
    char draft_[maximumLineLength + 1] = {};
};

} // namespace shell
