// Fuzz target: the receiving side of the global time base
// (docs/protocols/time.md), which takes every TimeSync frame a node hears.
//
// The input is a stream of frames, each a control byte (bits 7-6 the
// interface, bits 5-4 the sender's node less one, bits 3-0 the length)
// and a time step byte (the uptime advances by it times 7 ms), then the
// frame's bytes. Each frame is decoded and fed to a ClockServo, whose
// corrections are applied to a model clock as the kernel applies them.
// Checks: a refused frame is refused for a reason the specification gives
// and a decoded one re-encodes to the same bytes; a correction is only
// ever the time a FollowUp carried, made whole from its Sync's seconds, at
// the uptime of that Sync; the master followed is a sender heard; the
// measured bound stays within what the limits allow, and the drift within
// its clamp.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <dcos/internal/ClockServo.hpp>
#include <dcos/internal/TimeSyncMessage.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>

using namespace dcos::internal;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    ClockServo servo(9);
    servo.configure(dcos::TimeRole::Follower, 0, 1000);
    uint64_t base = 1'764'547'200ull * 1'000'000'000ull;
    uint64_t uptime = 0;
    // The last Sync decoded from each sender on each interface, to check a
    // correction against.
    struct Heard {
        bool valid = false;
        uint8_t sequence = 0;
        uint64_t seconds = 0;
        uint64_t at = 0;
    } heard[4][4]{};
    size_t at = 0;
    while (at + 2 <= size) {
        const uint8_t control = data[at];
        uptime += uint64_t{data[at + 1]} * 7'000'000u;
        at += 2;
        const uint8_t interface = control >> 6;
        const uint16_t node = static_cast<uint16_t>(((control >> 4) & 0x3) + 1);
        const size_t length = control & 0x0F;
        if (length > size - at) {
            break;
        }
        const uint8_t* bytes = data + at;
        at += length;
        TimeSyncFrame frame;
        const TimeSyncError error = decodeTimeSync(bytes, length, frame);
        if (error != TimeSyncError::None) {
            FUZZ_CHECK(error == TimeSyncError::WrongLength || error == TimeSyncError::UnknownKind ||
                       error == TimeSyncError::BadRank || error == TimeSyncError::BadInterval);
            servo.countMalformed();
            continue;
        }
        uint8_t again[kTimeSyncBytes];
        switch (frame.kind) {
        case TimeSyncKind::Sync: {
            FUZZ_CHECK(length == kTimeSyncBytes);
            encodeTimeSync(frame.sequence, frame.seconds, frame.rank, frame.intervalMs, again);
            FUZZ_CHECK(std::memcmp(again, bytes, kTimeSyncBytes) == 0);
            // Only a Sync the servo took can be paired: one it ignored (a
            // less preferred master) leaves the last one taken in force.
            const uint32_t ignoredBefore = servo.status(uptime).ignored;
            servo.onSync(interface, node, frame, uptime);
            if (servo.status(uptime).ignored == ignoredBefore && interface < kNetworkInterfaces) {
                heard[interface][node - 1] = {true, frame.sequence, frame.seconds, uptime};
            }
            break;
        }
        case TimeSyncKind::FollowUp: {
            FUZZ_CHECK(length == kTimeSyncBytes);
            encodeTimeFollowUp(frame.sequence, frame.nanosecondsLow, again);
            FUZZ_CHECK(std::memcmp(again, bytes, kTimeSyncBytes) == 0);
            const uint64_t before = servo.status(uptime).corrections;
            const ClockCorrection correction = servo.onFollowUp(
                interface, node, frame, uptime, [&base](uint64_t syncUptime) { return base + syncUptime; });
            if (!correction.apply) {
                break;
            }
            FUZZ_CHECK(servo.status(uptime).corrections == before + 1);
            const Heard& sync = heard[interface][node - 1];
            FUZZ_CHECK(sync.valid && sync.sequence == frame.sequence && correction.atUptimeNs == sync.at);
            uint64_t whole = 0;
            FUZZ_CHECK(timeOfDayOfFollowUp(sync.seconds, frame.nanosecondsLow, whole));
            FUZZ_CHECK(whole == correction.timeOfDayNs);
            FUZZ_CHECK(servo.status(uptime).masterNode == node);
            if (correction.timeOfDayNs >= correction.atUptimeNs) {
                base = correction.timeOfDayNs - correction.atUptimeNs;
            }
            break;
        }
        case TimeSyncKind::Probe:
            FUZZ_CHECK(length == kTimeProbeBytes);
            servo.onProbe(dcos::TimeProbe{interface, frame.sequence, node, base + uptime});
            break;
        }
    }
    const dcos::GlobalTimeStatus status = servo.status(uptime);
    FUZZ_CHECK(status.corrections <= status.followUpsReceived);
    // A correction in step is within the step limit of no prediction, or
    // within the residual limit of one over at most two 25.5 s intervals
    // at 1000 ppm.
    FUZZ_CHECK(status.largestOffsetNs <= dcos::kGlobalTimeStepConfirmNs ||
               status.largestOffsetNs <= dcos::kGlobalTimeResidualNs + 51'000'000);
    FUZZ_CHECK(status.driftPpb >= -1'000'000 && status.driftPpb <= 1'000'000);
    return 0;
}
