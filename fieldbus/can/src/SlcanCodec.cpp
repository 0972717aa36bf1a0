#include <can/SlcanCodec.hpp>

namespace can {

namespace {

// The `Sn` bit rates, in the order of the Lawicel manual (and Linux's slcan_bitrate_const).
constexpr uint32_t kBitrates[SlcanCodec::kBitrateCount] = {
    10000, 20000, 50000, 100000, 125000, 250000, 500000, 800000, 1000000,
};

// Hex digits of a standard and of an extended identifier.
constexpr uint8_t kStandardIdDigits = 3;
constexpr uint8_t kExtendedIdDigits = 8;
// Hex digits of a timestamp, of a status byte, and of a version reply.
constexpr uint8_t kTimestampDigits = 4;
constexpr uint8_t kByteDigits = 2;
constexpr uint8_t kVersionDigits = 4;
// A line holding a command letter and nothing else, and one with a single argument character.
constexpr size_t kBareCommandLength = 1;
constexpr size_t kOneArgumentLength = 2;

constexpr char kUpperHex[] = "0123456789ABCDEF";

int hexValue(char character)
{
    if (character >= '0' && character <= '9') {
        return character - '0';
    }
    if (character >= 'A' && character <= 'F') {
        return character - 'A' + 10;
    }
    if (character >= 'a' && character <= 'f') {
        return character - 'a' + 10;
    }
    return -1;
}

// Reads @p digits hex digits; false at the first character that is not one.
bool readHex(const char* text, uint8_t digits, uint32_t& value)
{
    value = 0;
    for (uint8_t i = 0; i < digits; ++i) {
        const int digit = hexValue(text[i]);
        if (digit < 0) {
            return false;
        }
        value = (value << 4) | static_cast<uint32_t>(digit);
    }
    return true;
}

bool isAlphanumeric(char character)
{
    return (character >= '0' && character <= '9') || (character >= 'A' && character <= 'Z')
           || (character >= 'a' && character <= 'z');
}

LinkResult<SlcanMessage> parseFrame(const char* line, size_t length)
{
    const char command = line[0];
    const bool extended = command == 'T' || command == 'R';
    const bool remote = command == 'r' || command == 'R';
    const uint8_t idDigits = extended ? kExtendedIdDigits : kStandardIdDigits;
    const size_t header = 1 + idDigits + 1; // command, identifier, DLC
    if (length < header) {
        return LinkError::InvalidLineLength;
    }
    uint32_t id = 0;
    if (!readHex(line + 1, idDigits, id)) {
        return LinkError::InvalidHexDigit;
    }
    const char dlc = line[1 + idDigits];
    if (dlc < '0' || dlc > static_cast<char>('0' + CanFrame::kMaxDataLength)) {
        return LinkError::InvalidDataLength;
    }
    const uint8_t dataLength = static_cast<uint8_t>(dlc - '0');
    const size_t dataDigits = remote ? 0 : static_cast<size_t>(dataLength) * kByteDigits;
    if (length != header + dataDigits && length != header + dataDigits + kTimestampDigits) {
        return LinkError::InvalidLineLength;
    }
    const IdFormat format = extended ? IdFormat::Extended : IdFormat::Standard;
    if (id > CanFrame::maxId(format)) {
        return LinkError::InvalidIdentifier;
    }
    uint8_t data[CanFrame::kMaxDataLength] = {};
    for (uint8_t i = 0; i < dataLength && !remote; ++i) {
        uint32_t value = 0;
        if (!readHex(line + header + i * kByteDigits, kByteDigits, value)) {
            return LinkError::InvalidHexDigit;
        }
        data[i] = static_cast<uint8_t>(value);
    }
    SlcanMessage message;
    message.kind = SlcanMessageKind::Frame;
    if (length == header + dataDigits + kTimestampDigits) {
        uint32_t timestamp = 0;
        if (!readHex(line + header + dataDigits, kTimestampDigits, timestamp)) {
            return LinkError::InvalidHexDigit;
        }
        // Lawicel's timestamps stay below 60000, but one beyond is kept as
        // it came rather than losing the frame over a field only read by people.
        message.hasTimestamp = true;
        message.timestampMs = static_cast<uint16_t>(timestamp);
    }
    const LinkResult<CanFrame> frame =
        remote ? CanFrame::makeRemote(id, format, dataLength) : CanFrame::makeData(id, format, data, dataLength);
    if (!frame.ok()) {
        return frame.error();
    }
    message.frame = frame.value();
    return message;
}

LinkResult<SlcanMessage> bareOrValue(const char* line, size_t length, SlcanMessageKind bare)
{
    SlcanMessage message;
    if (length == kBareCommandLength) {
        message.kind = bare;
        return message;
    }
    uint32_t value = 0;
    switch (bare) {
    case SlcanMessageKind::ReadStatusFlags:
        if (length != 1 + kByteDigits) {
            return LinkError::InvalidLineLength;
        }
        if (!readHex(line + 1, kByteDigits, value)) {
            return LinkError::InvalidHexDigit;
        }
        message.kind = SlcanMessageKind::StatusFlags;
        message.statusFlags = static_cast<uint8_t>(value);
        return message;
    case SlcanMessageKind::ReadVersion:
        if (length != 1 + kVersionDigits) {
            return LinkError::InvalidLineLength;
        }
        if (!readHex(line + 1, kVersionDigits, value)) {
            return LinkError::InvalidHexDigit;
        }
        message.kind = SlcanMessageKind::Version;
        message.hardwareVersion = static_cast<uint8_t>(value >> 8);
        message.softwareVersion = static_cast<uint8_t>(value & 0xFF);
        return message;
    case SlcanMessageKind::ReadSerial:
        if (length != 1 + SlcanMessage::kSerialLength) {
            return LinkError::InvalidLineLength;
        }
        for (uint8_t i = 0; i < SlcanMessage::kSerialLength; ++i) {
            if (!isAlphanumeric(line[1 + i])) {
                return LinkError::InvalidArgument;
            }
            message.serial[i] = line[1 + i];
        }
        message.kind = SlcanMessageKind::Serial;
        return message;
    default:
        return LinkError::InvalidLineLength;
    }
}

// Appends characters to a bounded buffer, remembering whether any did not fit.
class LineWriter {
public:
    LineWriter(char* output, size_t capacity) : output_(output), capacity_(capacity) {}

    void put(char character)
    {
        if (length_ < capacity_) {
            output_[length_] = character;
        } else {
            overflowed_ = true;
        }
        ++length_;
    }

    void putHex(uint32_t value, uint8_t digits)
    {
        for (uint8_t i = digits; i > 0; --i) {
            put(kUpperHex[(value >> ((i - 1) * 4)) & 0xF]);
        }
    }

    LinkResult<size_t> result() const
    {
        if (overflowed_) {
            return LinkError::BufferTooSmall;
        }
        return length_;
    }

private:
    char* output_;
    size_t capacity_;
    size_t length_ = 0;
    bool overflowed_ = false;
};

} // namespace

SlcanCodec::Outcome SlcanCodec::feed(uint8_t byte)
{
    const char character = static_cast<char>(byte);
    if (character == kCarriageReturn || character == kBell) {
        const bool wasEmpty = length_ == 0 && !overlong_;
        const bool wasOverlong = overlong_;
        const size_t length = length_;
        reset();
        if (wasOverlong) {
            return reject(LinkError::LineTooLong);
        }
        if (character == kBell) {
            if (!wasEmpty) {
                return reject(LinkError::LineInterrupted);
            }
            message_ = SlcanMessage();
            message_.kind = SlcanMessageKind::Error;
            ++statistics_.messages;
            return Outcome::Message;
        }
        if (wasEmpty) {
            message_ = SlcanMessage();
            message_.kind = SlcanMessageKind::Ok;
            ++statistics_.messages;
            return Outcome::Message;
        }
        const LinkResult<SlcanMessage> parsed = parseLine(line_, length);
        if (!parsed.ok()) {
            return reject(parsed.error());
        }
        message_ = parsed.value();
        ++statistics_.messages;
        return Outcome::Message;
    }
    if (character == kLineFeed && length_ == 0 && !overlong_) {
        return Outcome::Pending;
    }
    if (overlong_) {
        return Outcome::Pending;
    }
    if (length_ == kMaxLineLength) {
        overlong_ = true;
        return Outcome::Pending;
    }
    line_[length_++] = character;
    return Outcome::Pending;
}

void SlcanCodec::reset()
{
    length_ = 0;
    overlong_ = false;
}

SlcanCodec::Outcome SlcanCodec::reject(LinkError error)
{
    lastError_ = error;
    ++statistics_.rejected;
    switch (error) {
    case LinkError::InvalidHexDigit: ++statistics_.invalidHexDigit; break;
    case LinkError::LineTooLong: ++statistics_.lineTooLong; break;
    case LinkError::InvalidLineLength: ++statistics_.invalidLineLength; break;
    case LinkError::InvalidIdentifier: ++statistics_.invalidIdentifier; break;
    case LinkError::InvalidDataLength: ++statistics_.invalidDataLength; break;
    case LinkError::UnknownCommand: ++statistics_.unknownCommand; break;
    case LinkError::InvalidArgument: ++statistics_.invalidArgument; break;
    case LinkError::LineInterrupted: ++statistics_.lineInterrupted; break;
    default: break;
    }
    return Outcome::Rejected;
}

LinkResult<SlcanMessage> SlcanCodec::parseLine(const char* line, size_t length)
{
    SlcanMessage message;
    if (length == 0) {
        message.kind = SlcanMessageKind::Ok;
        return message;
    }
    if (line == nullptr) {
        return LinkError::InvalidArgument;
    }
    switch (line[0]) {
    case 't':
    case 'T':
    case 'r':
    case 'R':
        return parseFrame(line, length);
    case 'S':
        if (length != kOneArgumentLength) {
            return LinkError::InvalidLineLength;
        }
        if (line[1] < '0' || line[1] >= static_cast<char>('0' + kBitrateCount)) {
            return LinkError::InvalidArgument;
        }
        message.kind = SlcanMessageKind::SetBitrate;
        message.bitrateIndex = static_cast<uint8_t>(line[1] - '0');
        return message;
    case 'O':
    case 'C':
        if (length != kBareCommandLength) {
            return LinkError::InvalidLineLength;
        }
        message.kind = line[0] == 'O' ? SlcanMessageKind::Open : SlcanMessageKind::Close;
        return message;
    case 'F':
        return bareOrValue(line, length, SlcanMessageKind::ReadStatusFlags);
    case 'V':
        return bareOrValue(line, length, SlcanMessageKind::ReadVersion);
    case 'N':
        return bareOrValue(line, length, SlcanMessageKind::ReadSerial);
    case 'Z':
        // `Z` alone acknowledges an extended frame; `Z0`/`Z1` switch timestamps.
        if (length == kBareCommandLength) {
            message.kind = SlcanMessageKind::TransmitAck;
            message.ackFormat = IdFormat::Extended;
            return message;
        }
        if (length != kOneArgumentLength) {
            return LinkError::InvalidLineLength;
        }
        if (line[1] != '0' && line[1] != '1') {
            return LinkError::InvalidArgument;
        }
        message.kind = SlcanMessageKind::SetTimestamps;
        message.timestampsOn = line[1] == '1';
        return message;
    case 'z':
        if (length != kBareCommandLength) {
            return LinkError::InvalidLineLength;
        }
        message.kind = SlcanMessageKind::TransmitAck;
        message.ackFormat = IdFormat::Standard;
        return message;
    default:
        return LinkError::UnknownCommand;
    }
}

LinkResult<size_t> SlcanCodec::format(const SlcanMessage& message, char* output, size_t capacity)
{
    if (output == nullptr && capacity != 0) {
        return LinkError::InvalidArgument;
    }
    LineWriter writer(output, capacity);
    switch (message.kind) {
    case SlcanMessageKind::Frame: {
        const CanFrame& frame = message.frame;
        if (message.hasTimestamp && message.timestampMs > SlcanMessage::kMaxTimestampMs) {
            return LinkError::InvalidArgument;
        }
        const char letter = frame.isRemote() ? 'r' : 't';
        writer.put(frame.isExtended() ? static_cast<char>(letter - ('a' - 'A')) : letter);
        writer.putHex(frame.id(), frame.isExtended() ? kExtendedIdDigits : kStandardIdDigits);
        writer.put(static_cast<char>('0' + frame.length()));
        if (!frame.isRemote()) {
            for (uint8_t i = 0; i < frame.length(); ++i) {
                writer.putHex(frame.byte(i), kByteDigits);
            }
        }
        if (message.hasTimestamp) {
            writer.putHex(message.timestampMs, kTimestampDigits);
        }
        break;
    }
    case SlcanMessageKind::SetBitrate:
        if (message.bitrateIndex >= kBitrateCount) {
            return LinkError::InvalidArgument;
        }
        writer.put('S');
        writer.put(static_cast<char>('0' + message.bitrateIndex));
        break;
    case SlcanMessageKind::Open: writer.put('O'); break;
    case SlcanMessageKind::Close: writer.put('C'); break;
    case SlcanMessageKind::ReadStatusFlags: writer.put('F'); break;
    case SlcanMessageKind::StatusFlags:
        writer.put('F');
        writer.putHex(message.statusFlags, kByteDigits);
        break;
    case SlcanMessageKind::ReadVersion: writer.put('V'); break;
    case SlcanMessageKind::Version:
        writer.put('V');
        writer.putHex(message.hardwareVersion, kByteDigits);
        writer.putHex(message.softwareVersion, kByteDigits);
        break;
    case SlcanMessageKind::ReadSerial: writer.put('N'); break;
    case SlcanMessageKind::Serial:
        writer.put('N');
        for (uint8_t i = 0; i < SlcanMessage::kSerialLength; ++i) {
            if (!isAlphanumeric(message.serial[i])) {
                return LinkError::InvalidArgument;
            }
            writer.put(message.serial[i]);
        }
        break;
    case SlcanMessageKind::SetTimestamps:
        writer.put('Z');
        writer.put(message.timestampsOn ? '1' : '0');
        break;
    case SlcanMessageKind::Ok: break;
    case SlcanMessageKind::Error:
        // The error reply is the BELL alone, with no CR after it.
        writer.put(kBell);
        return writer.result();
    case SlcanMessageKind::TransmitAck:
        writer.put(message.ackFormat == IdFormat::Extended ? 'Z' : 'z');
        break;
    default:
        return LinkError::InvalidArgument;
    }
    writer.put(kCarriageReturn);
    return writer.result();
}

uint32_t SlcanCodec::bitrate(uint8_t index)
{
    return index < kBitrateCount ? kBitrates[index] : 0;
}

LinkResult<uint8_t> SlcanCodec::bitrateIndex(uint32_t bitsPerSecond)
{
    for (uint8_t i = 0; i < kBitrateCount; ++i) {
        if (kBitrates[i] == bitsPerSecond) {
            return i;
        }
    }
    return LinkError::InvalidArgument;
}

} // namespace can
