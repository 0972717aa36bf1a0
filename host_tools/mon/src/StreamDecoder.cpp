#include <hostmon/StreamDecoder.hpp>

#include <can/MessageIdentifier.hpp>

#include <cstdlib>

namespace hostmon {

namespace {

constexpr int64_t kWrapMs = 65536;
constexpr int64_t kNsPerMs = 1'000'000;
// A console line the node never ends (a runaway output without line
// ends) is handed over in pieces of this size, so memory stays bounded.
constexpr size_t kMaxLine = 4096;

} // namespace

bool isStreamFrame(const can::CanFrame& frame, uint8_t host, uint8_t node)
{
    const can::LinkResult<can::MessageIdentifier> id = can::MessageIdentifier::fromFrame(frame);
    return id.ok() && id.value().type() == can::MessageType::Monitoring && id.value().destination() == host &&
           id.value().source() == node;
}

int64_t TimeUnwrapper::unwrap(uint16_t timeMs, int64_t arrivalNs)
{
    if (!started_) {
        started_ = true;
        lastMs_ = timeMs;
        lastArrivalNs_ = arrivalNs;
        return lastMs_;
    }
    const int64_t elapsedMs = arrivalNs > lastArrivalNs_ ? (arrivalNs - lastArrivalNs_) / kNsPerMs : 0;
    const int64_t expected = lastMs_ + elapsedMs;
    const int64_t base = expected - (expected % kWrapMs) + timeMs;
    int64_t best = base;
    for (const int64_t candidate : {base - kWrapMs, base + kWrapMs}) {
        if (std::llabs(candidate - expected) < std::llabs(best - expected)) {
            best = candidate;
        }
    }
    lastMs_ = best;
    lastArrivalNs_ = arrivalNs;
    return best;
}

bool StreamDecoder::onFrame(const uint8_t* data, size_t length, int64_t arrivalNs, std::vector<StreamEvent>& out)
{
    sei::MonitorFrame frame;
    if (!sei::MonitorFrame::decode(data, length, frame)) {
        ++malformed_;
        return false;
    }
    switch (frame.kind) {
    case sei::MonitorFrameKind::Sample: {
        const int64_t ms = time_.unwrap(frame.timeMs, arrivalNs);
        if (!haveOrigin_) {
            haveOrigin_ = true;
            originMs_ = ms;
        }
        StreamEvent event;
        event.kind = StreamEvent::Kind::Sample;
        event.channel = frame.channel;
        event.seconds = static_cast<double>(ms - originMs_) / 1000.0;
        event.value = frame.value;
        out.push_back(event);
        break;
    }
    case sei::MonitorFrameKind::Log:
        if (haveSequence_ && frame.sequence != nextSequence_) {
            // The line in progress lost its continuation: hand it over as it
            // is, then say how much is missing.
            flush(out);
            StreamEvent gap;
            gap.kind = StreamEvent::Kind::LogGap;
            gap.count = static_cast<uint8_t>(frame.sequence - nextSequence_);
            logFramesLost_ += gap.count;
            out.push_back(gap);
        }
        haveSequence_ = true;
        nextSequence_ = static_cast<uint8_t>(frame.sequence + 1);
        takeText(frame.text, frame.textLength, out);
        break;
    case sei::MonitorFrameKind::Lost: {
        flush(out);
        StreamEvent lost;
        lost.kind = StreamEvent::Kind::LogLost;
        lost.count = frame.lostBytes;
        out.push_back(lost);
        break;
    }
    case sei::MonitorFrameKind::End: {
        flush(out);
        StreamEvent end;
        end.kind = StreamEvent::Kind::End;
        end.reason = frame.reason;
        out.push_back(end);
        break;
    }
    }
    return true;
}

void StreamDecoder::takeText(const uint8_t* text, size_t length, std::vector<StreamEvent>& out)
{
    for (size_t i = 0; i < length; ++i) {
        const char c = static_cast<char>(text[i]);
        if (c == '\n') {
            StreamEvent line;
            line.kind = StreamEvent::Kind::LogLine;
            line.text = printableLine(line_);
            line_.clear();
            out.push_back(line);
            continue;
        }
        line_.push_back(c);
        if (line_.size() >= kMaxLine) {
            flush(out);
        }
    }
}

void StreamDecoder::flush(std::vector<StreamEvent>& out)
{
    if (line_.empty()) {
        return;
    }
    StreamEvent line;
    line.kind = StreamEvent::Kind::LogLine;
    line.text = printableLine(line_);
    line_.clear();
    if (!line.text.empty()) {
        out.push_back(line);
    }
}

std::string printableLine(const std::string& raw)
{
    std::string shown;
    for (size_t i = 0; i < raw.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(raw[i]);
        if (c == 0x1B) {
            // ESC [ parameters final-byte: a terminal's control sequence.
            if (i + 1 < raw.size() && raw[i + 1] == '[') {
                i += 2;
                while (i < raw.size() && (static_cast<unsigned char>(raw[i]) < 0x40 ||
                                          static_cast<unsigned char>(raw[i]) > 0x7E)) {
                    ++i;
                }
            }
            continue;
        }
        if (c == '\b' || c == 0x7F) {
            if (!shown.empty()) {
                shown.pop_back();
            }
            continue;
        }
        if (c == '\t' || (c >= 0x20 && c < 0x7F) || c >= 0x80) {
            shown.push_back(static_cast<char>(c));
        }
    }
    return shown;
}

} // namespace hostmon
