// The global time base's encoder and decoder (TimeSyncMessage.hpp,
// docs/protocols/time.md). Pure code: no kernel state.
#include <dcos/internal/TimeSyncMessage.hpp>

namespace dcos::internal {

namespace {

constexpr uint8_t kKindShift = 6;
constexpr uint8_t kRankMask = 0x0F;
constexpr uint64_t kNanosecondsPerSecond = 1'000'000'000;
constexpr unsigned kLowBits = 56;
constexpr uint64_t kLowMask = (uint64_t{1} << kLowBits) - 1;
// A Sync's seconds fit 40 bits until the year 36812; the clock stops at 2399.
constexpr uint64_t kSecondsMask = (uint64_t{1} << 40) - 1;
// The follow-up's time lies within this of its Sync's whole seconds: the
// second the Sync was queued in, and the next, since the frame may go a
// little after the second turns.
constexpr uint64_t kFollowUpWindowNs = 2 * kNanosecondsPerSecond;

uint8_t header(TimeSyncKind kind, uint8_t sequence)
{
    return static_cast<uint8_t>((static_cast<uint8_t>(kind) << kKindShift) | (sequence & kTimeSyncSequenceMask));
}

void putBigEndian(uint8_t* at, uint64_t value, unsigned bytes)
{
    for (unsigned i = 0; i < bytes; ++i) {
        at[i] = static_cast<uint8_t>(value >> (8 * (bytes - 1 - i)));
    }
}

uint64_t getBigEndian(const uint8_t* at, unsigned bytes)
{
    uint64_t value = 0;
    for (unsigned i = 0; i < bytes; ++i) {
        value = (value << 8) | at[i];
    }
    return value;
}

} // namespace

const char* timeSyncErrorName(TimeSyncError error)
{
    switch (error) {
    case TimeSyncError::None: return "none";
    case TimeSyncError::WrongLength: return "wrong length";
    case TimeSyncError::UnknownKind: return "unknown kind";
    case TimeSyncError::BadRank: return "bad rank";
    case TimeSyncError::BadInterval: return "bad interval";
    }
    return "?";
}

void encodeTimeSync(uint8_t sequence, uint64_t seconds, uint8_t rank, uint32_t intervalMs,
                    uint8_t (&frame)[kTimeSyncBytes])
{
    frame[0] = header(TimeSyncKind::Sync, sequence);
    putBigEndian(frame + 1, seconds & kSecondsMask, 5);
    frame[6] = static_cast<uint8_t>(rank & kRankMask);
    uint32_t tenths = intervalMs / kTimeSyncIntervalUnitMs;
    tenths = tenths == 0 ? 1 : (tenths > 255 ? 255 : tenths);
    frame[7] = static_cast<uint8_t>(tenths);
}

void encodeTimeFollowUp(uint8_t sequence, uint64_t timeOfDayNs, uint8_t (&frame)[kTimeSyncBytes])
{
    frame[0] = header(TimeSyncKind::FollowUp, sequence);
    putBigEndian(frame + 1, timeOfDayNs & kLowMask, 7);
}

void encodeTimeProbe(uint8_t sequence, uint8_t (&frame)[kTimeProbeBytes])
{
    frame[0] = header(TimeSyncKind::Probe, sequence);
}

TimeSyncError decodeTimeSync(const uint8_t* bytes, size_t length, TimeSyncFrame& frame)
{
    frame = TimeSyncFrame{};
    if (length == 0) {
        return TimeSyncError::WrongLength;
    }
    const uint8_t kind = bytes[0] >> kKindShift;
    frame.sequence = bytes[0] & kTimeSyncSequenceMask;
    switch (kind) {
    case static_cast<uint8_t>(TimeSyncKind::Sync):
        if (length != kTimeSyncBytes) {
            return TimeSyncError::WrongLength;
        }
        if ((bytes[6] & ~kRankMask) != 0) {
            return TimeSyncError::BadRank;
        }
        if (bytes[7] == 0) {
            return TimeSyncError::BadInterval;
        }
        frame.kind = TimeSyncKind::Sync;
        frame.seconds = getBigEndian(bytes + 1, 5);
        frame.rank = bytes[6];
        frame.intervalMs = uint32_t{bytes[7]} * kTimeSyncIntervalUnitMs;
        return TimeSyncError::None;
    case static_cast<uint8_t>(TimeSyncKind::FollowUp):
        if (length != kTimeSyncBytes) {
            return TimeSyncError::WrongLength;
        }
        frame.kind = TimeSyncKind::FollowUp;
        frame.nanosecondsLow = getBigEndian(bytes + 1, 7);
        return TimeSyncError::None;
    case static_cast<uint8_t>(TimeSyncKind::Probe):
        if (length != kTimeProbeBytes) {
            return TimeSyncError::WrongLength;
        }
        frame.kind = TimeSyncKind::Probe;
        return TimeSyncError::None;
    default:
        return TimeSyncError::UnknownKind;
    }
}

bool timeOfDayOfFollowUp(uint64_t seconds, uint64_t nanosecondsLow, uint64_t& timeOfDayNs)
{
    if (seconds > kSecondsMask || nanosecondsLow > kLowMask) {
        return false;
    }
    // seconds * 1e9 < 2^40 * 2^30 = 2^70 would overflow in general; the
    // clock ends in 2399 (13.5e9 s), so refuse what it could never show.
    constexpr uint64_t kLastSeconds = (~uint64_t{0} - kFollowUpWindowNs) / kNanosecondsPerSecond;
    if (seconds > kLastSeconds) {
        return false;
    }
    const uint64_t start = seconds * kNanosecondsPerSecond;
    // The first value at or after start with the given low bits.
    uint64_t candidate = (start & ~kLowMask) | nanosecondsLow;
    if (candidate < start) {
        candidate += uint64_t{1} << kLowBits;
        if (candidate < start) {
            return false; // Wrapped past 2^64.
        }
    }
    if (candidate - start >= kFollowUpWindowNs) {
        return false;
    }
    timeOfDayNs = candidate;
    return true;
}

} // namespace dcos::internal
