// The global time base's decisions (ClockServo.hpp, docs/protocols/time.md).
// Pure code: no kernel state.
#include <dcos/internal/ClockServo.hpp>

namespace dcos {

const char* timeRoleName(TimeRole role)
{
    switch (role) {
    case TimeRole::Off: return "off";
    case TimeRole::Follower: return "follower";
    case TimeRole::Master: return "master";
    }
    return "?";
}

} // namespace dcos

namespace dcos::internal {

namespace {

constexpr uint64_t kNanosecondsPerMs = 1'000'000;
// The drift estimate's limit, in parts per billion: 1000 ppm, five times a
// poor crystal's tolerance.
constexpr int64_t kLargestDriftPpb = 1'000'000;
// The longest time over which the drift predicts an offset: two of the
// longest intervals, so that prediction * 1e9 and offset * 1e9 fit 64 bits.
constexpr uint64_t kLongestPredictionNs = 2 * uint64_t{kLongestTimeSyncIntervalMs} * kNanosecondsPerMs;

uint64_t magnitude(int64_t value)
{
    return value < 0 ? uint64_t{0} - static_cast<uint64_t>(value) : static_cast<uint64_t>(value);
}

} // namespace

void ClockServo::configure(TimeRole role, uint8_t rank, uint32_t intervalMs)
{
    if (role != role_ || rank != rank_) {
        following_ = false;
        inStepCount_ = 0;
        holding_ = false;
        driftKnown_ = false;
        for (PendingSync& pending : pending_) {
            pending.valid = false;
        }
    }
    role_ = role;
    rank_ = rank;
    intervalMs_ = intervalMs;
}

bool ClockServo::masterGone(uint64_t nowUptime) const
{
    const uint64_t silence = uint64_t{kSilentIntervals} * masterIntervalMs_ * kNanosecondsPerMs;
    return nowUptime - masterHeardUptime_ > silence;
}

bool ClockServo::sending(uint64_t nowUptime) const
{
    if (role_ != TimeRole::Master) {
        return false;
    }
    // A master follows only a more preferred one (onSync), and stays quiet
    // while it hears it.
    return !following_ || masterGone(nowUptime);
}

uint8_t ClockServo::nextSequence()
{
    const uint8_t sequence = sequence_;
    sequence_ = static_cast<uint8_t>((sequence_ + 1) & kTimeSyncSequenceMask);
    ++status_.syncsSent;
    return sequence;
}

void ClockServo::onSync(uint8_t interface, uint16_t node, const TimeSyncFrame& sync, uint64_t rxUptime)
{
    ++status_.syncsReceived;
    if (role_ == TimeRole::Off || interface >= kNetworkInterfaces) {
        return;
    }
    const TimeMasterKey key{sync.rank, node};
    if (role_ == TimeRole::Master && !(key < TimeMasterKey{rank_, ownNode_})) {
        // A less preferred master, which goes quiet when it hears this one.
        ++status_.ignored;
        return;
    }
    const bool gone = following_ && masterGone(rxUptime);
    const bool same = following_ && key == master_ && !gone;
    if (following_ && !same && !(key < master_) && !gone) {
        ++status_.ignored;
        return;
    }
    if (!same) {
        // A new master, or the same one back after it was taken as gone: its
        // first correction measures how far apart the two clocks were, not
        // a drift.
        masterChanged_ = true;
        holding_ = false;
        if (!following_) {
            inStepCount_ = 0;
        }
        following_ = true;
        master_ = key;
    }
    masterInterface_ = interface;
    masterIntervalMs_ = sync.intervalMs;
    masterHeardUptime_ = rxUptime;
    PendingSync& pending = pending_[interface];
    pending.valid = true;
    pending.node = node;
    pending.sequence = sync.sequence;
    pending.seconds = sync.seconds;
    pending.rxUptime = rxUptime;
}

ClockCorrection ClockServo::pair(uint8_t interface, uint16_t node, const TimeSyncFrame& followUp, uint64_t rxUptime,
                                 uint64_t& syncUptime)
{
    ++status_.followUpsReceived;
    if (role_ == TimeRole::Off || interface >= kNetworkInterfaces) {
        return {};
    }
    PendingSync& pending = pending_[interface];
    // The FollowUp comes right after its Sync; one older than two of the
    // master's intervals would pair with a Sync of an earlier round.
    const uint64_t window = 2 * uint64_t{masterIntervalMs_} * kNanosecondsPerMs;
    if (!pending.valid || !following_ || pending.node != node || master_.node != node ||
        pending.sequence != followUp.sequence || rxUptime - pending.rxUptime > window) {
        ++status_.unpaired;
        return {};
    }
    pending.valid = false;
    ClockCorrection correction;
    if (!timeOfDayOfFollowUp(pending.seconds, followUp.nanosecondsLow, correction.timeOfDayNs)) {
        ++status_.malformed;
        return {};
    }
    correction.apply = true;
    correction.atUptimeNs = pending.rxUptime;
    syncUptime = pending.rxUptime;
    return correction;
}

ClockCorrection ClockServo::judge(uint64_t masterTime, uint64_t localTime, uint64_t syncUptime)
{
    const int64_t offset = static_cast<int64_t>(masterTime - localTime);
    const uint64_t elapsed = syncUptime - lastSyncUptime_;
    const bool wasInStep = inStepCount_ >= 1;
    // A step the next sync confirmed: applied, but no measure of the drift
    // or of the bound, and the node stays in step.
    bool step = false;
    if (wasInStep) {
        // What the drift measured so far says this offset should be; a
        // first correction from a new master, or one before the drift is
        // known, is only held to the step limit.
        int64_t predicted = 0;
        uint64_t limit = kGlobalTimeStepConfirmNs;
        if (driftKnown_ && !masterChanged_ && elapsed <= kLongestPredictionNs) {
            predicted = -(static_cast<int64_t>(status_.driftPpb) * static_cast<int64_t>(elapsed)) / 1'000'000'000;
            limit = kGlobalTimeResidualNs;
        }
        const int64_t residual = offset - predicted;
        if (magnitude(residual) > limit) {
            // One bad timestamp, one bad message, or the master's clock was
            // set: only the next sync tells.
            if (!holding_ || magnitude(residual - heldResidual_) > limit) {
                holding_ = true;
                heldResidual_ = residual;
                ++status_.held;
                return {};
            }
            step = true;
        }
    }
    holding_ = false;
    ++status_.corrections;
    status_.lastOffsetNs = offset;
    if (wasInStep && !step) {
        const uint64_t size = magnitude(offset);
        if (size > status_.largestOffsetNs) {
            status_.largestOffsetNs = size;
        }
        if (!masterChanged_ && elapsed != 0 && elapsed <= kLongestPredictionNs) {
            // The master gained offset on this node over elapsed: this node
            // is slow by offset / elapsed. |offset| is at most the residual
            // limit plus 1000 ppm of elapsed, under 62 ms, so offset * 1e9
            // fits 64 bits; the estimate is held to +-1000 ppm so that the
            // next prediction stays as small.
            int64_t drift = -(offset * 1'000'000'000) / static_cast<int64_t>(elapsed);
            drift = drift > kLargestDriftPpb ? kLargestDriftPpb : (drift < -kLargestDriftPpb ? -kLargestDriftPpb : drift);
            status_.driftPpb = static_cast<int32_t>(drift);
            driftKnown_ = true;
        }
    }
    if (masterChanged_ && !step) {
        driftKnown_ = false; // A rate against the previous master.
    }
    masterChanged_ = false;
    lastSyncUptime_ = syncUptime;
    if (!step) {
        ++inStepCount_;
    }
    return {true, masterTime, syncUptime};
}

void ClockServo::onProbe(const TimeProbe& probe)
{
    ++status_.probes;
    probes_[probeNext_] = probe;
    probeNext_ = (probeNext_ + 1) % GlobalTime::kProbes;
    if (probeCount_ < GlobalTime::kProbes) {
        ++probeCount_;
    }
}

GlobalTimeStatus ClockServo::status(uint64_t nowUptime) const
{
    GlobalTimeStatus out = status_;
    out.role = role_;
    out.rank = rank_;
    out.intervalMs = intervalMs_;
    out.sending = sending(nowUptime);
    out.following = following_ && !masterGone(nowUptime);
    out.inStep = out.following && inStepCount_ >= 2;
    if (out.sending) {
        out.masterNode = ownNode_;
        out.masterRank = rank_;
        out.masterIntervalMs = intervalMs_;
    } else if (following_) {
        out.masterNode = master_.node;
        out.masterRank = master_.rank;
        out.masterInterface = masterInterface_;
        out.masterIntervalMs = masterIntervalMs_;
    }
    return out;
}

size_t ClockServo::probes(TimeProbe* out, size_t capacity) const
{
    const size_t count = probeCount_ < capacity ? probeCount_ : capacity;
    // The newest count of them, oldest first.
    const size_t first = (probeNext_ + GlobalTime::kProbes - count) % GlobalTime::kProbes;
    for (size_t i = 0; i < count; ++i) {
        out[i] = probes_[(first + i) % GlobalTime::kProbes];
    }
    return count;
}

} // namespace dcos::internal
