#include <shell/LineEditor.hpp>

namespace shell {

namespace {
constexpr char backspace = '\b';
constexpr char deleteKey = 0x7F;
constexpr char controlC = 0x03;
constexpr char controlU = 0x15;
} // namespace

void LineEditor::erase(size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        echo_.put(backspace);
        echo_.put(' ');
        echo_.put(backspace);
    }
}

LineEditor::Event LineEditor::finish()
{
    echo_.put('\r');
    echo_.put('\n');
    const bool overflowed = overflowed_;
    buffer_[length_] = '\0';
    overflowed_ = false;
    lineDelivered_ = true;
    if (overflowed) {
        length_ = 0;
        buffer_[0] = '\0';
        return Event::LineTooLong;
    }
    return Event::LineReady;
}

LineEditor::Event LineEditor::feed(char character)
{
    const bool afterCarriageReturn = lastWasCarriageReturn_;
    lastWasCarriageReturn_ = character == '\r';

    if (lineDelivered_) {
        // The previous line has been handed out; start the next one.
        lineDelivered_ = false;
        length_ = 0;
        buffer_[0] = '\0';
    }

    switch (character) {
    case '\r':
        return finish();
    case '\n':
        // CR LF is one line end, not an end followed by an empty line.
        return afterCarriageReturn ? Event::None : finish();
    case backspace:
    case deleteKey:
        if (length_ > 0 && !overflowed_) {
            --length_;
            erase(1);
        }
        return Event::None;
    case controlU:
        if (!overflowed_) {
            erase(length_);
        }
        length_ = 0;
        overflowed_ = false;
        return Event::None;
    case controlC:
        echo_.put('^');
        echo_.put('C');
        echo_.put('\r');
        echo_.put('\n');
        length_ = 0;
        overflowed_ = false;
        buffer_[0] = '\0';
        return Event::Cancelled;
    default:
        break;
    }
    if (static_cast<unsigned char>(character) < 0x20) {
        return Event::None; // Other control characters are ignored.
    }
    if (overflowed_) {
        return Event::None;
    }
    if (length_ == maximumLineLength) {
        overflowed_ = true;
        return Event::None;
    }
    buffer_[length_++] = character;
    echo_.put(character);
    return Event::None;
}

} // namespace shell
