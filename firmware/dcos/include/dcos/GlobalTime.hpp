// The global time base (seed 5.6, 4.2.4): every node's system clock kept
// within a stated bound of one time master's, over the fieldbus.
//
// A master sends a Sync every interval on each attached link, and after it
// a FollowUp with its time of day at the moment the Sync ended on the bus
// (docs/protocols/time.md). Every other node sets the base of its system
// clock so that the time it read at that same moment becomes the master's.
// Only the base changes, as SetSystemClock changes it (seed 7.5): uptimes,
// intervals and time-outs in progress are untouched, while day-clock alarms
// and SleepTill follow the time of day.
//
// Between syncs a node's clock runs at its own crystal's rate, so the bound
// is its drift against the master's times the interval, plus the error of
// the two interrupt timestamps (docs/protocols/time.md, "The bound").
//
// Several nodes may be masters, each with a rank: the most preferred that
// is heard (the lowest rank, then the lowest node) sends, the others stay
// quiet and follow it, and when it has been silent for three of its
// intervals the next one takes over. A follower follows the most preferred
// master it hears. Once a node is in step, a correction that strays from
// what its measured drift predicts by more than kGlobalTimeResidualNs
// (kGlobalTimeStepConfirmNs before the drift is known) is applied only when
// the next sync confirms it, so one bad timestamp or message cannot throw
// the clocks out.
#pragma once

#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// What a node does for the global time base.
enum class TimeRole : uint8_t {
    Off = 0,      ///< Ignores syncs and sends none: a free-running clock.
    Follower = 1, ///< Follows the most preferred master it hears (the default).
    Master = 2,   ///< Sends syncs while no more preferred master is heard; follows one that is.
};

const char* timeRoleName(TimeRole role);

/// A correction larger than this, once in step, waits for the next sync's confirmation.
constexpr uint64_t kGlobalTimeStepConfirmNs = 10'000'000;
/// Once the drift is known: a correction further than this from the drift's
/// prediction waits for the next sync's confirmation.
constexpr uint64_t kGlobalTimeResidualNs = 200'000;
/// The default sync interval.
constexpr uint32_t kDefaultTimeSyncIntervalMs = 1000;

/// A time-of-day probe: a TimeSync Probe frame from anyone, and this node's
/// time of day at the end of that frame. Every node notes the same frame
/// at the same moment, so comparing their notes measures how far apart
/// their clocks really are (docs/protocols/time.md, "Probes").
struct TimeProbe {
    uint8_t interface = 0;
    uint8_t sequence = 0;
    uint32_t source = 0;     ///< The sender's physical address.
    uint64_t timeOfDayNs = 0;
};

/// The state of the global time base on this node.
struct GlobalTimeStatus {
    TimeRole role = TimeRole::Follower;
    uint8_t rank = 0;             ///< As a master.
    uint32_t intervalMs = 0;      ///< As a master.
    bool sending = false;         ///< A master that is the one sending now.
    bool following = false;       ///< A master is followed (its syncs are taken).
    uint16_t masterNode = 0;      ///< The master followed, or that this node is.
    uint8_t masterRank = 0;
    uint8_t masterInterface = 0;
    uint32_t masterIntervalMs = 0;
    bool inStep = false;          ///< Two corrections in a row from the master followed.
    // Counters since boot.
    uint32_t syncsSent = 0;
    uint32_t followUpsSent = 0;
    uint32_t syncsReceived = 0;
    uint32_t followUpsReceived = 0;
    uint32_t corrections = 0;
    uint32_t unpaired = 0;        ///< FollowUps with no Sync to pair (a lost or stale Sync).
    uint32_t ignored = 0;         ///< Syncs of a master not followed (a less preferred one).
    uint32_t held = 0;            ///< Corrections above the step limit held for confirmation.
    uint32_t malformed = 0;
    uint32_t probes = 0;
    // The measured bound.
    int64_t lastOffsetNs = 0;     ///< The last correction: master minus this node.
    uint64_t largestOffsetNs = 0; ///< The largest correction since in step: the measured bound.
    int32_t driftPpb = 0;         ///< This node's rate against the master's, in parts per billion (+: fast).
};

class GlobalTime {
public:
    /// Sets this node's role (privileged). @p rank (0 to 15) and
    /// @p intervalMs (100 to 25,500, a multiple of 100) only for a master.
    /// InvalidArgument for values outside these, NotPermitted for a task
    /// that is not a super user.
    static Status SetRole(TimeRole role, uint8_t rank = 0, uint32_t intervalMs = kDefaultTimeSyncIntervalMs);
    static GlobalTimeStatus GetStatus();
    /// The probes noted, oldest first: up to @p capacity into @p probes;
    /// returns how many were written. The node keeps the last kProbes.
    static size_t GetProbes(TimeProbe* probes, size_t capacity);
    /// Sends a Probe on every attached link (privileged).
    static Status SendProbe(uint8_t sequence);

    static constexpr size_t kProbes = 8;
};

inline constexpr GlobalTime globalTime{};

} // namespace dcos
