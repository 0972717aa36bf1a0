// Encoded priority of a task inside a deadline scope (dissertation 7.4.1, Fig. 7.6).
//
// The dynamic scheduler orders deadline tasks by static priority first and
// then by latest start time (deadline - execution period), which behaves like
// Minimum Slack First but, unlike slack, does not change as time advances.
// Both are packed into one 64-bit value so that the common comparison is a
// single integer compare:
//
//     63      59 58                                   0
//     | static  |  latest start time, ns since boot,   |
//     | priority|  saturated to 59 bits                |
//
// Resolution and range: the latest start time is kept in whole nanoseconds of
// the monotonic system time (the timer agent's "increment", not the wall
// clock, so SetSystemClock never reorders the queue). 59 bits of nanoseconds
// span 2^59 ns, about 18.3 years, which is the validity period the seed gives
// for the system clock itself. Later latest start times saturate to the
// largest value (they still sort after every earlier one), and a latest start
// time before boot (execution period longer than the time to the deadline)
// saturates to 0, the most urgent value, because such a task is already late.
//
// Ties in the encoded value are broken, in this order, by the shorter
// deadline period (relative urgency), the shorter execution period (shortest
// processing time completes one task properly under overload), and finally
// first come first served, which the DeadlineQueue supplies.
#pragma once

#include <stdint.h>

namespace dcos::internal {

/// The composite scheduling key of one task in a deadline scope.
class DeadlineKey {
public:
    /// Bit position of the 5-bit static priority.
    static constexpr unsigned kPriorityShift = 59;
    /// Largest static priority (lowest urgency).
    static constexpr uint8_t kLowestPriority = 31;
    /// Largest latest start time the key can hold, in ns since boot.
    static constexpr uint64_t kMaxLatestStart = (uint64_t{1} << kPriorityShift) - 1;

    /// Creates the key of a lowest-priority task that can start at the end of time.
    constexpr DeadlineKey() = default;

    /// Computes the key of a task that arrived at @p arrival (ns since boot).
    ///
    /// The deadline is arrival + deadline period (saturating at 2^64-1 ns)
    /// and the latest start time is deadline - execution period, both as the
    /// seed defines them. A priority above 31 is treated as 31 so that it can
    /// never spill into the time bits; the agent validates priorities before.
    static constexpr DeadlineKey make(uint8_t priority, uint64_t arrival, uint64_t deadlinePeriod,
                                      uint64_t executionPeriod)
    {
        const uint64_t deadline
            = deadlinePeriod > UINT64_MAX - arrival ? UINT64_MAX : arrival + deadlinePeriod;
        const uint64_t latestStart = executionPeriod > deadline ? 0 : deadline - executionPeriod;
        DeadlineKey key;
        key.encoded_ = encode(priority, latestStart);
        key.deadline_ = deadline;
        key.deadlinePeriod_ = deadlinePeriod;
        key.executionPeriod_ = executionPeriod;
        return key;
    }

    /// Packs a static priority and a latest start time (ns since boot) into 64 bits.
    static constexpr uint64_t encode(uint8_t priority, uint64_t latestStart)
    {
        const uint64_t p = priority > kLowestPriority ? kLowestPriority : priority;
        const uint64_t t = latestStart > kMaxLatestStart ? kMaxLatestStart : latestStart;
        return (p << kPriorityShift) | t;
    }

    /// The packed priority and latest start time.
    constexpr uint64_t encoded() const { return encoded_; }
    /// The static priority, 0..31.
    constexpr uint8_t priority() const { return static_cast<uint8_t>(encoded_ >> kPriorityShift); }
    /// The latest start time as held in the key (saturated), in ns since boot.
    constexpr uint64_t latestStart() const { return encoded_ & kMaxLatestStart; }
    /// The absolute deadline in ns since boot, for scheduling-failure detection.
    constexpr uint64_t deadline() const { return deadline_; }
    /// The relative deadline period in ns, the first tie-break.
    constexpr uint64_t deadlinePeriod() const { return deadlinePeriod_; }
    /// The execution period in ns, the second tie-break.
    constexpr uint64_t executionPeriod() const { return executionPeriod_; }

    /// Whether this key must run before @p other; false for a full tie.
    ///
    /// A full tie is left to first come first served by the caller.
    constexpr bool precedes(const DeadlineKey& other) const
    {
        if (encoded_ != other.encoded_) {
            return encoded_ < other.encoded_;
        }
        if (deadlinePeriod_ != other.deadlinePeriod_) {
            return deadlinePeriod_ < other.deadlinePeriod_;
        }
        return executionPeriod_ < other.executionPeriod_;
    }

private:
    uint64_t encoded_ = UINT64_MAX;
    uint64_t deadline_ = UINT64_MAX;
    uint64_t deadlinePeriod_ = UINT64_MAX;
    uint64_t executionPeriod_ = UINT64_MAX;
};

} // namespace dcos::internal
