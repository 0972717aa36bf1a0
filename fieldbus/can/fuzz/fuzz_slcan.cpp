// Fuzz target: the slcan parser fed an arbitrary byte stream.
//
// Checks: every line ends in exactly one message or one refusal, counted
// once in the statistics under its reason; every message the parser decodes
// formats back into the line it came from (hex digits in upper case) and
// that line decodes to the same message; and the same bytes fed one at a
// time or as whole lines through parseLine() agree.
#include "FuzzCheck.hpp"

#include <can/SlcanCodec.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace {

using namespace can;

bool sameMessage(const SlcanMessage& a, const SlcanMessage& b)
{
    if (a.kind != b.kind) {
        return false;
    }
    switch (a.kind) {
    case SlcanMessageKind::Frame:
        return a.frame == b.frame && a.hasTimestamp == b.hasTimestamp && (!a.hasTimestamp || a.timestampMs == b.timestampMs);
    case SlcanMessageKind::SetBitrate: return a.bitrateIndex == b.bitrateIndex;
    case SlcanMessageKind::StatusFlags: return a.statusFlags == b.statusFlags;
    case SlcanMessageKind::Version:
        return a.hardwareVersion == b.hardwareVersion && a.softwareVersion == b.softwareVersion;
    case SlcanMessageKind::Serial: return std::memcmp(a.serial, b.serial, SlcanMessage::kSerialLength) == 0;
    case SlcanMessageKind::SetTimestamps: return a.timestampsOn == b.timestampsOn;
    case SlcanMessageKind::TransmitAck: return a.ackFormat == b.ackFormat;
    default: return true;
    }
}

uint32_t reasonCounters(const SlcanCodec::Statistics& s)
{
    return s.invalidHexDigit + s.lineTooLong + s.invalidLineLength + s.invalidIdentifier + s.invalidDataLength
           + s.unknownCommand + s.invalidArgument + s.lineInterrupted;
}

char upper(char character)
{
    return character >= 'a' && character <= 'z' ? static_cast<char>(character - 'a' + 'A') : character;
}

// A line the parser took is written back as it came, but for the case of its
// hex digits (written in upper case): so no digit was misread.
void checkCanonical(const SlcanMessage& message, const char* line, size_t length)
{
    char written[SlcanCodec::kMaxLineLength + 1];
    const LinkResult<size_t> count = SlcanCodec::format(message, written, sizeof(written));
    if (!count.ok()) {
        return; // A timestamp beyond Lawicel's minute; checkRoundTrip() checks that.
    }
    FUZZ_CHECK(count.value() == length + 1 && written[length] == '\r');
    for (size_t i = 0; i < length; ++i) {
        const bool exact = i == 0 || message.kind == SlcanMessageKind::Serial;
        FUZZ_CHECK(exact ? written[i] == line[i] : written[i] == upper(line[i]));
    }
}

void checkRoundTrip(const SlcanMessage& message)
{
    char line[SlcanCodec::kMaxLineLength + 1];
    const LinkResult<size_t> written = SlcanCodec::format(message, line, sizeof(line));
    if (!written.ok()) {
        // Only a timestamp beyond Lawicel's minute is read but not written.
        FUZZ_CHECK(message.kind == SlcanMessageKind::Frame && message.hasTimestamp
                   && message.timestampMs > SlcanMessage::kMaxTimestampMs);
        return;
    }
    FUZZ_CHECK(written.value() >= 1 && written.value() <= sizeof(line));
    SlcanCodec codec;
    int messages = 0;
    for (size_t i = 0; i < written.value(); ++i) {
        const SlcanCodec::Outcome outcome = codec.feed(static_cast<uint8_t>(line[i]));
        FUZZ_CHECK(outcome != SlcanCodec::Outcome::Rejected);
        if (outcome == SlcanCodec::Outcome::Message) {
            FUZZ_CHECK(i == written.value() - 1);
            FUZZ_CHECK(sameMessage(codec.message(), message));
            ++messages;
        }
    }
    FUZZ_CHECK(messages == 1);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    SlcanCodec codec;
    uint32_t messages = 0;
    uint32_t rejections = 0;
    // The line as the parser should see it: what came since the last line end.
    char line[SlcanCodec::kMaxLineLength];
    size_t length = 0;
    bool overlong = false;

    for (size_t i = 0; i < size; ++i) {
        const char character = static_cast<char>(data[i]);
        const SlcanCodec::Outcome outcome = codec.feed(data[i]);
        const bool ends = character == '\r' || character == '\a';
        FUZZ_CHECK(ends == (outcome != SlcanCodec::Outcome::Pending));
        if (outcome == SlcanCodec::Outcome::Message) {
            ++messages;
            FUZZ_CHECK(!overlong);
            if (character == '\r') {
                // The same line through parseLine() decodes the same.
                const LinkResult<SlcanMessage> direct = SlcanCodec::parseLine(line, length);
                FUZZ_CHECK(direct.ok() && sameMessage(direct.value(), codec.message()));
                checkCanonical(codec.message(), line, length);
            } else {
                FUZZ_CHECK(length == 0 && codec.message().kind == SlcanMessageKind::Error);
            }
            checkRoundTrip(codec.message());
        } else if (outcome == SlcanCodec::Outcome::Rejected) {
            ++rejections;
            FUZZ_CHECK(codec.lastError() != LinkError::Ok);
            if (overlong) {
                FUZZ_CHECK(codec.lastError() == LinkError::LineTooLong);
            } else if (character == '\a') {
                FUZZ_CHECK(codec.lastError() == LinkError::LineInterrupted);
            } else {
                const LinkResult<SlcanMessage> direct = SlcanCodec::parseLine(line, length);
                FUZZ_CHECK(!direct.ok() && direct.error() == codec.lastError());
            }
        }
        if (ends) {
            length = 0;
            overlong = false;
        } else if (character == '\n' && length == 0 && !overlong) {
            // Skipped at the start of a line.
        } else if (length == sizeof(line)) {
            overlong = true;
        } else if (!overlong) {
            line[length++] = character;
        }
        const SlcanCodec::Statistics& statistics = codec.statistics();
        FUZZ_CHECK(statistics.messages == messages);
        FUZZ_CHECK(statistics.rejected == rejections);
        FUZZ_CHECK(reasonCounters(statistics) == rejections);
    }
    return 0;
}
