// The decisions of the global time base (GlobalTime.hpp,
// docs/protocols/time.md), as pure code: which master to follow, which
// FollowUp belongs to which Sync, when a master sends, and what correction
// a pair gives. The kernel glue (src/network/GlobalTime.cpp) feeds it the
// decoded frames with their interrupt timestamps and applies what it
// returns; the host tests drive it with made-up times.
//
// Times: "uptime" is the node's monotonic nanoseconds (TimerAgent::Uptime),
// as read at a frame's interrupt; "time of day" is base + uptime, in
// nanoseconds since 1970.
#pragma once

#include <dcos/GlobalTime.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/TimeSyncMessage.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// A master's identity on the network: lower is more preferred.
struct TimeMasterKey {
    uint8_t rank = 0;
    uint16_t node = 0;

    constexpr bool operator<(const TimeMasterKey& other) const
    {
        return rank != other.rank ? rank < other.rank : node < other.node;
    }
    constexpr bool operator==(const TimeMasterKey& other) const { return rank == other.rank && node == other.node; }
};

/// What a FollowUp asks of the clock.
struct ClockCorrection {
    bool apply = false;
    /// Set the base so that the time of day at uptime atUptimeNs is timeOfDayNs.
    uint64_t timeOfDayNs = 0;
    uint64_t atUptimeNs = 0;
};

class ClockServo {
public:
    /// A master is taken as gone after this many of its intervals without a Sync.
    static constexpr uint32_t kSilentIntervals = 3;

    /// This node: its logical node number, for ranking itself among masters.
    explicit ClockServo(uint16_t ownNode = 0) : ownNode_(ownNode) {}

    void setOwnNode(uint16_t node) { ownNode_ = node; }

    /// Sets the role; a changed role forgets the master followed.
    void configure(TimeRole role, uint8_t rank, uint32_t intervalMs);

    /// Whether this node, a master, sends a Sync at @p nowUptime: no more
    /// preferred master has been heard within kSilentIntervals of its intervals.
    bool sending(uint64_t nowUptime) const;
    /// The next sequence number for a Sync; counts it as sent.
    uint8_t nextSequence();
    void countFollowUpSent() { ++status_.followUpsSent; }

    /// A Sync from node @p node, received over @p interface at @p rxUptime.
    void onSync(uint8_t interface, uint16_t node, const TimeSyncFrame& sync, uint64_t rxUptime);
    /// A FollowUp from @p node over @p interface, received at @p rxUptime;
    /// @p timeOfDayAtSync is this node's time of day at its Sync's uptime
    /// (the base now plus that uptime), from which the offset is measured.
    /// @p timeOfDayAtSync is only read when the FollowUp pairs with a Sync:
    /// the caller passes a function of the Sync's uptime.
    template <typename TimeOfDayAt>
    ClockCorrection onFollowUp(uint8_t interface, uint16_t node, const TimeSyncFrame& followUp, uint64_t rxUptime,
                               TimeOfDayAt timeOfDayAt);
    void countMalformed() { ++status_.malformed; }
    void onProbe(const TimeProbe& probe);

    GlobalTimeStatus status(uint64_t nowUptime) const;
    size_t probes(TimeProbe* out, size_t capacity) const;

private:
    struct PendingSync {
        bool valid = false;
        uint16_t node = 0;
        uint8_t sequence = 0;
        uint64_t seconds = 0;
        uint64_t rxUptime = 0;
    };

    bool masterGone(uint64_t nowUptime) const;
    ClockCorrection pair(uint8_t interface, uint16_t node, const TimeSyncFrame& followUp, uint64_t rxUptime,
                         uint64_t& syncUptime);
    ClockCorrection judge(uint64_t masterTime, uint64_t localTime, uint64_t syncUptime);

    uint16_t ownNode_;
    TimeRole role_ = TimeRole::Follower;
    uint8_t rank_ = 0;
    uint32_t intervalMs_ = kDefaultTimeSyncIntervalMs;
    uint8_t sequence_ = 0;

    // The master followed (a better one than this node, if it is a master).
    bool following_ = false;
    TimeMasterKey master_{};
    uint8_t masterInterface_ = 0;
    uint32_t masterIntervalMs_ = 0;
    uint64_t masterHeardUptime_ = 0;

    PendingSync pending_[kNetworkInterfaces];

    // The servo's memory: the previous correction, for the drift and for
    // confirming a large one.
    uint32_t inStepCount_ = 0;      // Corrections in a row from the master followed.
    uint64_t lastSyncUptime_ = 0;   // The uptime of the Sync of the last correction.
    bool masterChanged_ = false;    // The next correction is the first from a new master.
    bool driftKnown_ = false;       // status_.driftPpb is measured against the master followed.
    bool holding_ = false;          // A correction out of line waits for confirmation.
    int64_t heldResidual_ = 0;      // Its offset less the drift's prediction.

    GlobalTimeStatus status_{};
    TimeProbe probes_[GlobalTime::kProbes];
    size_t probeNext_ = 0;
    size_t probeCount_ = 0;
};

template <typename TimeOfDayAt>
ClockCorrection ClockServo::onFollowUp(uint8_t interface, uint16_t node, const TimeSyncFrame& followUp,
                                       uint64_t rxUptime, TimeOfDayAt timeOfDayAt)
{
    uint64_t syncUptime = 0;
    ClockCorrection paired = pair(interface, node, followUp, rxUptime, syncUptime);
    if (!paired.apply) {
        return paired;
    }
    return judge(paired.timeOfDayNs, timeOfDayAt(syncUptime), syncUptime);
}

} // namespace dcos::internal
