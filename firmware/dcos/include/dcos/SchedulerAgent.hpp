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
    static Status Yield();
    /// Enters the deadline-driven real-time scope: the task is scheduled by
    /// static priority, then latest start time (deadline - execution
    /// period), before every task outside a scope. A deadline passed before
    /// ClearDeadline raises a timing exception.
    static Status SetDeadline(DeadlineStart start, uint64_t executionPeriodNs, uint64_t deadlinePeriodNs);
    /// Leaves the real-time scope.
    static Status ClearDeadline();
    /// Sets the time-slice quantum for time-sliced tasks (privileged).
    static Status SetTimeSliceQuantum(uint64_t nanoseconds);
    /// Starts measuring the execution time of a task, excluding preemption.
    static Status StartProfiling(ObjectId task);
    /// Ends one measurement interval and records it.
    static Status StopProfiling(ObjectId task);
    static Result<TimingInfo> GetTimingInfo(ObjectId task);
};

inline constexpr SchedulerAgent schedulerAgent{};

} // namespace dcos
