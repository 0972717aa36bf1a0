// The system messages of the global time base (seed 5.6, 4.2.4, 7.5):
// how a time master tells the other nodes its clock.
// docs/protocols/time.md is the specification; this is its only encoder
// and decoder, pure code shared by the kernel, the host tests and the fuzz
// target.
//
// Message type 0x01 (TimeSync, docs/protocols/can.md), to the broadcast
// address, at priority 0. Byte 0 says what the frame is:
//
//     byte 0   bits 7-6 kind (0 Sync, 1 FollowUp, 2 Probe; 3 is refused)
//              bits 5-0 sequence number, 0 to 63
//     Sync     bytes 1-5 the master's time of day in whole seconds when it
//                        queued the sync (40 bits, big-endian)
//              byte 6    bits 3-0 the master's rank (0 most preferred);
//                        bits 7-4 zero
//              byte 7    the master's sync interval in tenths of a second (1-255)
//     FollowUp bytes 1-7 the master's time of day, in nanoseconds modulo
//                        2^56 (big-endian), at the end of its Sync frame
//     Probe    byte 0 only
//
// A sync is a two-step exchange, as IEEE 1588's two-step clocks do it: the
// moment that counts is the end of the Sync frame, which every node on a
// CAN bus sees at once (the sender as its transmit interrupt, the others as
// their receive interrupt). The master learns it only after the frame has
// gone, so it sends it in the FollowUp, and each node sets its clock's base
// so that the time it read at its own interrupt becomes the master's.
//
// The FollowUp's 56 bits of nanoseconds repeat every 2.28 years; the Sync's
// whole seconds, read a little before the frame went, say which repetition
// is meant.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// What a TimeSync frame is.
enum class TimeSyncKind : uint8_t {
    Sync = 0,
    FollowUp = 1,
    Probe = 2,
};

/// Bytes of a Sync and of a FollowUp; a Probe is one byte.
constexpr size_t kTimeSyncBytes = 8;
constexpr size_t kTimeProbeBytes = 1;
/// Sequence numbers run from 0 to this and wrap.
constexpr uint8_t kTimeSyncSequenceMask = 0x3F;
/// The least preferred master rank.
constexpr uint8_t kLastTimeMasterRank = 15;
/// The sync interval a Sync can announce, in milliseconds.
constexpr uint32_t kTimeSyncIntervalUnitMs = 100;
constexpr uint32_t kShortestTimeSyncIntervalMs = kTimeSyncIntervalUnitMs;
constexpr uint32_t kLongestTimeSyncIntervalMs = 255 * kTimeSyncIntervalUnitMs;

/// One decoded frame; the fields of the other kinds are zero.
struct TimeSyncFrame {
    TimeSyncKind kind = TimeSyncKind::Sync;
    uint8_t sequence = 0;
    // Sync
    uint64_t seconds = 0;     ///< The master's whole seconds when it queued the sync.
    uint8_t rank = 0;
    uint32_t intervalMs = 0;  ///< A multiple of kTimeSyncIntervalUnitMs.
    // FollowUp
    uint64_t nanosecondsLow = 0; ///< The master's time of day at the Sync's end, modulo 2^56.
};

/// Why a frame was refused.
enum class TimeSyncError : uint8_t {
    None,
    WrongLength,   ///< Not eight bytes (one for a probe).
    UnknownKind,   ///< Kind 3.
    BadRank,       ///< A Sync whose byte 6 has its high bits set.
    BadInterval,   ///< A Sync announcing an interval of 0.
};

const char* timeSyncErrorName(TimeSyncError error);

void encodeTimeSync(uint8_t sequence, uint64_t seconds, uint8_t rank, uint32_t intervalMs,
                    uint8_t (&frame)[kTimeSyncBytes]);
void encodeTimeFollowUp(uint8_t sequence, uint64_t timeOfDayNs, uint8_t (&frame)[kTimeSyncBytes]);
void encodeTimeProbe(uint8_t sequence, uint8_t (&frame)[kTimeProbeBytes]);

/// Decodes any TimeSync frame.
TimeSyncError decodeTimeSync(const uint8_t* bytes, size_t length, TimeSyncFrame& frame);

/// The time of day a FollowUp carries, whole again: the value whose low 56
/// bits are @p nanosecondsLow and which lies in the two seconds from
/// @p seconds (its Sync's) on. False when none does: a FollowUp that does
/// not belong to that Sync.
bool timeOfDayOfFollowUp(uint64_t seconds, uint64_t nanosecondsLow, uint64_t& timeOfDayNs);

} // namespace dcos::internal
