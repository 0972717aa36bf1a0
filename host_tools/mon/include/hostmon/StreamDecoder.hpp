// The host's reading of a node's monitoring stream (docs/protocols/monitor.md):
// which frames on the bus belong to it, and what they say as events a tool
// prints: samples with the node's time in seconds (the 16-bit millisecond
// time unwrapped), console output as whole lines, the Log frames a gap in
// their sequence says were lost, the bytes a Lost frame says the node's
// ring dropped, and the stream's end. Pure code on the node's own frame
// decoder (sei::MonitorFrame), so tool and node cannot disagree on a byte.
#pragma once

#include <sei/MonitorFrame.hpp>

#include <can/CanFrame.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace hostmon {

/// Whether @p frame is a frame of the stream node @p node sends to host
/// @p host: an extended data frame of type Monitoring from @p node to @p host.
bool isStreamFrame(const can::CanFrame& frame, uint8_t host, uint8_t node);

/// Turns the node's uptime in milliseconds modulo 65536 back into a time
/// that keeps growing. Each frame's arrival on the host's clock (any
/// monotonic one: the lab bus's emulated time, a SocketCAN timestamp) says
/// roughly how much time passed since the last; of the times with the
/// frame's low 16 bits, the one nearest to that guess is taken. So a wrap
/// is found however many samples were lost in between, as long as the
/// host's guess is within 32.7 s.
class TimeUnwrapper {
public:
    int64_t unwrap(uint16_t timeMs, int64_t arrivalNs);

private:
    bool started_ = false;
    int64_t lastMs_ = 0;
    int64_t lastArrivalNs_ = 0;
};

struct StreamEvent {
    enum class Kind {
        Sample,  ///< channel, seconds, value
        LogLine, ///< text: one console line without its line end
        LogGap,  ///< count: Log frames lost (their sequence skipped)
        LogLost, ///< count: console bytes the node's ring dropped
        End,     ///< reason
    };
    Kind kind = Kind::Sample;
    uint8_t channel = 0;
    /// Seconds of the node's time since the stream's first sample.
    double seconds = 0;
    int32_t value = 0;
    std::string text;
    unsigned count = 0;
    sei::MonitorEndReason reason = sei::MonitorEndReason::LeaseExpired;
};

class StreamDecoder {
public:
    /// Reads one frame's @p length bytes, which arrived at @p arrivalNs;
    /// appends what it says to @p out. False, and counted, for a frame that
    /// is not exactly one of the stream's layouts.
    bool onFrame(const uint8_t* data, size_t length, int64_t arrivalNs, std::vector<StreamEvent>& out);

    /// Hands over a console line begun but not ended (a prompt), when the
    /// console has been quiet a while or the stream ends.
    void flush(std::vector<StreamEvent>& out);
    bool hasPartialLine() const { return !line_.empty(); }

    unsigned malformed() const { return malformed_; }
    /// Log frames lost over the stream, by their sequence.
    unsigned logFramesLost() const { return logFramesLost_; }

private:
    void takeText(const uint8_t* text, size_t length, std::vector<StreamEvent>& out);

    TimeUnwrapper time_;
    bool haveOrigin_ = false;
    int64_t originMs_ = 0;
    bool haveSequence_ = false;
    uint8_t nextSequence_ = 0;
    std::string line_;
    unsigned malformed_ = 0;
    unsigned logFramesLost_ = 0;
};

/// A console line as a terminal would show it: printable characters and
/// tabs kept; a backspace takes the character before it; escape sequences
/// (a shell's cursor movement) and other control characters left out.
std::string printableLine(const std::string& raw);

} // namespace hostmon
