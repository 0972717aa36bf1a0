// Turns a stream of terminal key presses into complete command lines.
//
// The editor echoes what it accepts, so the operator sees exactly what the
// controller will execute. It understands backspace (BS or DEL), Ctrl-U
// (erase the line), Ctrl-C (abandon the line) and CR, LF or CR LF as the
// end of a line. A line longer than the buffer is not cut silently: the
// editor stops storing, keeps reading to the end of the line, and reports
// the line as too long so nothing half-typed is executed.
#pragma once

#include <stddef.h>

#include <runtime/Format.hpp>

namespace shell {

class LineEditor {
public:
    /// The longest line accepted, in characters.
    static constexpr size_t maximumLineLength = 255;

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

private:
    void erase(size_t count);
    Event finish();

    runtime::CharacterSink& echo_;
    char buffer_[maximumLineLength + 1] = {};
    size_t length_ = 0;
    bool overflowed_ = false;
    bool lastWasCarriageReturn_ = false;
    bool lineDelivered_ = false;
};

} // namespace shell
