// Fuzz target: the host's reading of a node's monitoring stream
// (docs/protocols/monitor.md), which takes whatever arrives on the bus in
// frames of type 0x41 to this host: sei::MonitorFrame::decode and
// hostmon::StreamDecoder.
//
// The input is a script of frames: one byte of length (taken modulo 10, so
// that 9, one too many for a classic frame, is tried too), then that many
// data bytes, then one byte of time passing on the host's clock (in units
// of 100 ms). Checks: decode accepts exactly the frames this file's own
// reading of the page's table accepts, and a frame it accepts encodes back
// to the same bytes; the decoder gives one event per sample, console text
// comes back in lines without line ends, a gap never claims more than 255
// frames, unwrapped time never jumps backwards by more than the 16-bit
// field allows, and the malformed count is exactly the refused frames.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <hostmon/StreamDecoder.hpp>
#include <sei/MonitorFrame.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {

// The page's table, read independently of MonitorFrame.cpp.
bool pageAllows(const uint8_t* data, size_t length)
{
    if (length == 0 || length > 8) {
        return false;
    }
    switch (data[0]) {
    case 0x01: return length == 8 && data[1] <= 7;
    case 0x02: return length >= 3;
    case 0x03: return length == 3 && (data[1] | data[2]) != 0;
    case 0x04: return length == 2 && data[1] >= 1 && data[1] <= 3;
    default: return false;
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* input, size_t size)
{
    hostmon::StreamDecoder decoder;
    int64_t clockNs = 0;
    unsigned refused = 0;
    bool haveTime = false;
    double lastSeconds = 0;
    size_t at = 0;
    while (at < size) {
        const size_t length = input[at++] % 10;
        uint8_t data[9] = {};
        size_t taken = 0;
        while (taken < length && at < size) {
            data[taken++] = input[at++];
        }
        if (at < size) {
            clockNs += static_cast<int64_t>(input[at++]) * 100'000'000;
        }

        sei::MonitorFrame frame;
        const bool accepted = sei::MonitorFrame::decode(data, taken, frame);
        FUZZ_CHECK(accepted == pageAllows(data, taken));
        if (accepted) {
            uint8_t again[sei::kMonitorFrameMax] = {};
            const size_t encoded = frame.encode(again);
            FUZZ_CHECK(encoded == taken);
            for (size_t i = 0; i < taken; ++i) {
                FUZZ_CHECK(again[i] == data[i]);
            }
        } else {
            ++refused;
        }

        std::vector<hostmon::StreamEvent> events;
        const bool read = decoder.onFrame(data, taken, clockNs, events);
        FUZZ_CHECK(read == accepted);
        unsigned sampleEvents = 0;
        for (const hostmon::StreamEvent& event : events) {
            switch (event.kind) {
            case hostmon::StreamEvent::Kind::Sample:
                ++sampleEvents;
                FUZZ_CHECK(event.channel <= 7);
                if (haveTime) {
                    // The nearest time with these low bits is never more
                    // than half the field's range before the last.
                    FUZZ_CHECK(event.seconds >= lastSeconds - 32.768 - 1e-6);
                }
                haveTime = true;
                lastSeconds = event.seconds;
                break;
            case hostmon::StreamEvent::Kind::LogLine:
                for (const char c : event.text) {
                    FUZZ_CHECK(c != '\n' && c != '\r');
                }
                break;
            case hostmon::StreamEvent::Kind::LogGap: FUZZ_CHECK(event.count >= 1 && event.count <= 255); break;
            case hostmon::StreamEvent::Kind::LogLost: FUZZ_CHECK(event.count >= 1 && event.count <= 0xFFFF); break;
            case hostmon::StreamEvent::Kind::End: break;
            }
        }
        FUZZ_CHECK(sampleEvents == (accepted && frame.kind == sei::MonitorFrameKind::Sample ? 1u : 0u));
    }
    FUZZ_CHECK(decoder.malformed() == refused);
    std::vector<hostmon::StreamEvent> rest;
    decoder.flush(rest);
    FUZZ_CHECK(!decoder.hasPartialLine());
    return 0;
}
