// The scheduler agent's application interface (seed 7.4).
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/TaskAgent.hpp>

#include <stdint.h>

namespace dcos {

/// When SetDeadline starts the real-time scope.
enum class DeadlineStart : uint8_t {
    Now,         ///< At once ("set now").
    AtNextBlock, ///< When the task is next readied after blocking ("set later").
};

/// The scheduler agent interface object.
class SchedulerAgent {
public:
    /// Gives the CPU to the next ready task of the same priority (round robin).
    Status Yield() const;
    /// Enters the deadline-driven real-time scope: the task is scheduled by
    /// static priority, then latest start time (deadline - execution
    /// period), before every task outside a scope. A deadline passed before
    /// ClearDeadline raises a timing exception.
    Status SetDeadline(DeadlineStart start, uint64_t executionPeriodNs, uint64_t deadlinePeriodNs) const;
    /// Leaves the real-time scope.
    Status ClearDeadline() const;
    /// Sets the time-slice quantum for time-sliced tasks (privileged).
    Status SetTimeSliceQuantum(uint64_t nanoseconds) const;
    /// Starts measuring the execution time of a task, excluding preemption.
    Status StartProfiling(ObjectId task) const;
    /// Ends one measurement interval and records it.
    Status StopProfiling(ObjectId task) const;
    Result<TimingInfo> GetTimingInfo(ObjectId task) const;
};

inline constexpr SchedulerAgent schedulerAgent{};

} // namespace dcos
