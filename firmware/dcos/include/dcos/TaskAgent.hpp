// The task agent's application interface (seed 7.6).
//
// Applications call the agents through interface objects (seed 7.2.4): here
// dcos::taskAgent. Every method takes logical ids, never pointers to kernel
// objects, so that the protection issue can move tasks to ring 3 behind a
// trap, and the network issue can make each primitive remote, without
// changing application code. Time-outs are 64-bit nanosecond counts.
#pragma once

#include <dcos/DateTime.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// Time-out values for services that wait.
constexpr uint64_t kPoll = 0;                  ///< Do not wait: fail with WouldBlock at once.
constexpr uint64_t kWaitForever = ~uint64_t{0}; ///< Wait without a time-out.

/// The highest (0) and lowest (31) static priorities.
constexpr uint8_t kHighestPriority = 0;
constexpr uint8_t kLowestPriority = 31;

/// The smallest stack a task may ask for. A task's stack also carries the
/// frames of interrupts that nest while it runs, and of its signal and
/// exception handlers.
constexpr size_t kMinimumStackSize = 2048;

/// What a task runs. It receives the argument given to Create; when it
/// returns, the task deletes itself.
using TaskEntry = void (*)(uintptr_t argument);

/// Attributes of a new task (seed 7.6).
struct TaskAttributes {
    const char* name = nullptr;       ///< Optional name for NameToObject, at most 15 characters.
    uint8_t priority = 16;            ///< Static priority, 0 (highest) to 31.
    size_t stackSize = 4096;          ///< Bytes of stack, at least kMinimumStackSize.
    bool timeSlicing = false;         ///< Share the CPU with equal-priority tasks in quanta.
    bool floatingPoint = false;       ///< Save and restore the FPU registers for this task.
    bool newProcess = false;          ///< Start a process of its own rather than join the creator's.
    Visibility visibility = Visibility::Local; ///< Who may find it by name.
    bool superUser = false;           ///< Privileged; only a super-user task may grant it.
};

/// The seed's task states (Fig. 7.10).
enum class TaskState : uint8_t {
    NonExistent,
    Spawning,
    Ready,
    Executing,
    Blocked,
    Suspended,
    Terminating,
};

/// How ReceiveEvent matches the requested event set.
enum class EventWait : uint8_t {
    Any, ///< Any one of the events.
    All, ///< Every one of the events.
};

/// Exception classes (seed 7.6.1).
enum class ExceptionClass : uint8_t {
    Timing,       ///< A missed deadline; ignored without a handler.
    Synchronous,  ///< Caused by the instruction: divide error, overflow, bound, FPU error.
    Asynchronous, ///< Caused by hardware (NMI, machine check) or thrown by another task.
    Fatal,        ///< Irrecoverable (protection, page, invalid opcode, double fault); always terminates.
};

/// What the kernel tells an exception handler.
struct ExceptionInfo {
    ExceptionClass exceptionClass;
    uint8_t vector;          ///< CPU vector for processor exceptions; 0xFF when raised in software.
    uint32_t errorCode;      ///< The CPU's error code, or the code passed to ThrowException.
    uint32_t instruction;    ///< Address of the faulting instruction, when there is one.
    /// For a synchronous exception the faulting instruction cannot simply be
    /// retried. A handler that can recover names a function here; the task
    /// continues in it (and ends when it returns). Left null, the task ends.
    void (*resumeIn)();
};

/// What an exception handler asks the kernel to do next.
enum class ExceptionAction : uint8_t {
    Continue,  ///< Continue where the task was (timing, asynchronous), or in resumeIn.
    Terminate, ///< End the task, recovering its objects.
};

using SignalHandler = void (*)(unsigned signal);
using ExceptionHandler = ExceptionAction (*)(ExceptionInfo& info);

/// Execution time statistics of a task (GetTimingInfo).
struct TimingInfo {
    uint32_t samples;        ///< Completed StartProfiling/StopProfiling intervals.
    uint64_t minimumNs;
    uint64_t averageNs;
    uint64_t maximumNs;
};

/// The task agent interface object.
class TaskAgent {
public:
    /// Creates a task running entry(argument). Returns its id. O(1) except
    /// for the stack allocation, which is a configuration-class O(N).
    static Result<ObjectId> Create(const TaskAttributes& attributes, TaskEntry entry, uintptr_t argument);
    /// Ends the calling task (suicide); does not return on success.
    static Status Delete();
    /// Ends another task, blocked, suspended or ready, and recovers its objects.
    static Status KillTask(ObjectId task);
    static Status Suspend(ObjectId task);
    static Status Resume(ObjectId task);
    static Status ChangePriority(ObjectId task, uint8_t priority);
    /// Blocks the caller for an interval.
    static Status SleepFor(uint64_t nanoseconds);
    /// Blocks the caller until a time of day.
    static Status SleepTill(const DateTime& time);
    /// Sets event flags of a task; allowed from interrupt handlers.
    static Status PostEvent(ObjectId task, uint32_t events);
    /// Waits for any or all of events, polling (kPoll) or with a time-out.
    /// Returns the events received, which are cleared.
    static Result<uint32_t> ReceiveEvent(uint32_t events, EventWait mode, uint64_t timeout);
    /// Sends signal 0-31 to a task; allowed from interrupt handlers.
    static Status SendSignal(ObjectId task, unsigned signal);
    static Status SetSignalHandler(SignalHandler handler);
    /// Sets the caller's signal mask (bit n set = signal n held); returns the previous mask.
    static Result<uint32_t> SetSignalMask(uint32_t mask);
    static Status SetExceptionHandler(ExceptionHandler handler);
    /// Raises an exception of the given class in a task.
    static Status ThrowException(ObjectId task, ExceptionClass exceptionClass, uint32_t code);
    /// The caller's own id.
    static ObjectId IdOfSelf();
    /// Looks a task up by name (O(N)).
    static Result<ObjectId> NameToObject(const char* name);
    /// The state of a task, as the seed names it.
    static Result<TaskState> GetState(ObjectId task);
    /// The static priority of a task.
    static Result<uint8_t> GetPriority(ObjectId task);
    /// Activates count more task slots (privileged configuration service).
    static Status AddObjects(size_t count);
};

inline constexpr TaskAgent taskAgent{};

} // namespace dcos
