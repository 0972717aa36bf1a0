#include <shell/LineEditor.hpp>

namespace shell {

namespace {
constexpr char backspace = '\b';
constexpr char deleteKey = 0x7F;
constexpr char escapeKey = 0x1B;
constexpr char controlC = 0x03;
constexpr char controlU = 0x15;

// ECMA-48, 5.4: a control sequence's parameter bytes are 0x30-0x3F, its
// intermediate bytes 0x20-0x2F, and its final byte 0x40-0x7E.
constexpr bool isFinalByte(char c) { return c >= 0x40 && c <= 0x7E; }

size_t textLength(const char* text)
{
    size_t length = 0;
    while (text[length] != '\0') {
        ++length;
    }
    return length;
}

void copyText(char* destination, const char* source, size_t capacity)
{
    size_t i = 0;
    for (; i + 1 < capacity && source[i] != '\0'; ++i) {
        destination[i] = source[i];
    }
    destination[i] = '\0';
}

bool sameText(const char* a, const char* b)
{
    size_t i = 0;
    for (; a[i] != '\0' && a[i] == b[i]; ++i) {
    }
    return a[i] == b[i];
}
} // namespace

void LineEditor::erase(size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        echo_.put(backspace);
        echo_.put(' ');
        echo_.put(backspace);
    }
}

void LineEditor::moveLeft(size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        echo_.put(backspace);
    }
    cursor_ -= count;
}

void LineEditor::moveRight(size_t count)
{
    // Writing the characters under the cursor moves it without a sequence.
    for (size_t i = 0; i < count; ++i) {
        echo_.put(buffer_[cursor_ + i]);
    }
    cursor_ += count;
}

void LineEditor::insert(char character)
{
    for (size_t i = length_; i > cursor_; --i) {
        buffer_[i] = buffer_[i - 1];
    }
    buffer_[cursor_] = character;
    ++length_;
    // Redraw from the new character to the end, then step back to just after it.
    for (size_t i = cursor_; i < length_; ++i) {
        echo_.put(buffer_[i]);
    }
    for (size_t i = cursor_ + 1; i < length_; ++i) {
        echo_.put(backspace);
    }
    ++cursor_;
}

void LineEditor::deleteUnderCursor()
{
    if (cursor_ == length_) {
        return;
    }
    for (size_t i = cursor_; i + 1 < length_; ++i) {
        buffer_[i] = buffer_[i + 1];
    }
    --length_;
    for (size_t i = cursor_; i < length_; ++i) {
        echo_.put(buffer_[i]);
    }
    echo_.put(' ');
    for (size_t i = cursor_; i <= length_; ++i) {
        echo_.put(backspace);
    }
}

void LineEditor::deleteBeforeCursor()
{
    if (cursor_ == 0) {
        return;
    }
    if (cursor_ == length_) {
        --length_;
        --cursor_;
        erase(1);
        return;
    }
    moveLeft(1);
    deleteUnderCursor();
}

void LineEditor::replaceLine(const char* text)
{
    moveLeft(cursor_);
    const size_t oldLength = length_;
    copyText(buffer_, text, sizeof buffer_);
    length_ = textLength(buffer_);
    for (size_t i = 0; i < length_; ++i) {
        echo_.put(buffer_[i]);
    }
    // Blank what is left of a longer old line, then come back.
    for (size_t i = length_; i < oldLength; ++i) {
        echo_.put(' ');
    }
    for (size_t i = length_; i < oldLength; ++i) {
        echo_.put(backspace);
    }
    cursor_ = length_;
}

void LineEditor::remember()
{
    buffer_[length_] = '\0';
    if (length_ == 0) {
        return;
    }
    if (historyCount_ > 0 && sameText(history_[historyNewest_], buffer_)) {
        return; // The same command again adds nothing to walk through.
    }
    historyNewest_ = historyCount_ == 0 ? 0 : (historyNewest_ + 1) % kHistoryDepth;
    copyText(history_[historyNewest_], buffer_, sizeof history_[0]);
    historyCount_ = historyCount_ < kHistoryDepth ? historyCount_ + 1 : kHistoryDepth;
}

void LineEditor::recall(int direction)
{
    if (overflowed_) {
        return;
    }
    const size_t target = direction > 0 ? browsing_ + 1 : (browsing_ == 0 ? 0 : browsing_ - 1);
    if (target == browsing_ || target > historyCount_) {
        return;
    }
    if (browsing_ == 0) {
        buffer_[length_] = '\0';
        copyText(draft_, buffer_, sizeof draft_);
    }
    browsing_ = target;
    if (browsing_ == 0) {
        replaceLine(draft_);
    } else {
        replaceLine(history_[(historyNewest_ + kHistoryDepth - (browsing_ - 1)) % kHistoryDepth]);
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
    browsing_ = 0;
    if (overflowed) {
        length_ = 0;
        cursor_ = 0;
        buffer_[0] = '\0';
        return Event::LineTooLong;
    }
    remember();
    return Event::LineReady;
}

void LineEditor::runSequence(char final)
{
    if (overflowed_) {
        return;
    }
    // A parameter of "1" or none is the key itself; "1;5" and the like are
    // the key with a modifier, which the editor does not give a meaning.
    const bool plain = sequenceLength_ == 0 || (sequenceLength_ == 1 && sequence_[0] == '1');
    if (final == '~') {
        // VT220 keys: ESC [ n ~.
        if (sequenceLength_ == 1) {
            switch (sequence_[0]) {
            case '1':
            case '7':
                moveLeft(cursor_);
                break;
            case '4':
            case '8':
                moveRight(length_ - cursor_);
                break;
            case '3':
                deleteUnderCursor();
                break;
            default:
                break;
            }
        }
        return;
    }
    if (!plain) {
        return;
    }
    switch (final) {
    case 'A':
        recall(+1);
        break;
    case 'B':
        recall(-1);
        break;
    case 'C':
        if (cursor_ < length_) {
            moveRight(1);
        }
        break;
    case 'D':
        if (cursor_ > 0) {
            moveLeft(1);
        }
        break;
    case 'H':
        moveLeft(cursor_);
        break;
    case 'F':
        moveRight(length_ - cursor_);
        break;
    default:
        break;
    }
}

LineEditor::Event LineEditor::handleEscape(char character)
{
    switch (escape_) {
    case EscapeState::Escape:
        if (character == '[') {
            escape_ = EscapeState::ControlSequence;
        } else if (character == 'O') {
            escape_ = EscapeState::SingleShift;
        } else {
            escape_ = EscapeState::None; // ESC and one character (Alt-key): dropped.
        }
        return Event::None;
    case EscapeState::SingleShift:
        escape_ = EscapeState::None;
        sequenceLength_ = 0;
        runSequence(character);
        return Event::None;
    case EscapeState::ControlSequence:
        if (isFinalByte(character)) {
            escape_ = EscapeState::None;
            if (!sequenceTooLong_) {
                runSequence(character);
            }
            sequenceLength_ = 0;
            sequenceTooLong_ = false;
            return Event::None;
        }
        if (static_cast<unsigned char>(character) < 0x20 || static_cast<unsigned char>(character) > 0x3F) {
            // Not part of a control sequence: the sequence was broken off.
            // The character is taken as typed, so a lost final byte costs
            // no more than the sequence itself.
            escape_ = EscapeState::None;
            sequenceLength_ = 0;
            sequenceTooLong_ = false;
            return feedText(character);
        }
        if (sequenceLength_ < kMaximumSequenceLength) {
            sequence_[sequenceLength_++] = character;
        } else {
            sequenceTooLong_ = true;
        }
        return Event::None;
    case EscapeState::None:
        break;
    }
    return Event::None;
}

LineEditor::Event LineEditor::feed(char character)
{
    if (lineDelivered_) {
        // The previous line has been handed out; start the next one.
        lineDelivered_ = false;
        length_ = 0;
        cursor_ = 0;
        buffer_[0] = '\0';
    }
    if (escape_ != EscapeState::None) {
        lastWasCarriageReturn_ = false;
        return handleEscape(character);
    }
    if (character == escapeKey) {
        lastWasCarriageReturn_ = false;
        escape_ = EscapeState::Escape;
        sequenceLength_ = 0;
        sequenceTooLong_ = false;
        return Event::None;
    }
    return feedText(character);
}

LineEditor::Event LineEditor::feedText(char character)
{
    const bool afterCarriageReturn = lastWasCarriageReturn_;
    lastWasCarriageReturn_ = character == '\r';

    switch (character) {
    case '\r':
        return finish();
    case '\n':
        // CR LF is one line end, not an end followed by an empty line.
        return afterCarriageReturn ? Event::None : finish();
    case backspace:
    case deleteKey:
        if (!overflowed_) {
            deleteBeforeCursor();
        }
        return Event::None;
    case controlU:
        if (!overflowed_) {
            moveRight(length_ - cursor_);
            erase(length_);
        }
        length_ = 0;
        cursor_ = 0;
        overflowed_ = false;
        return Event::None;
    case controlC:
        echo_.put('^');
        echo_.put('C');
        echo_.put('\r');
        echo_.put('\n');
        length_ = 0;
        cursor_ = 0;
        overflowed_ = false;
        browsing_ = 0;
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
    insert(character);
    return Event::None;
}

} // namespace shell
