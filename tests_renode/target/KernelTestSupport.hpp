// Helpers the kernel's on-target tests share: a trace of what ran in which
// order, and control of the test (shell) task's own priority.
#pragma once

#include "TargetTest.hpp"

#include <dcos/TaskAgent.hpp>

#include <stddef.h>
#include <stdint.h>

namespace target_test {

/// A short record of events, in order, written by tasks and handlers.
class Trace {
public:
    static void clear();
    /// Appends one character; safe from tasks and interrupt handlers.
    static void record(char mark);
    static const char* text();
    /// Prints the trace and compares it with expected.
    static bool expect(shell::Shell& shell, const char* expected);
};

/// Runs the test task at priority 0, so tasks it creates wait until it
/// lets them run, and restores its priority when it goes out of scope.
class HoldScheduling {
public:
    HoldScheduling();
    ~HoldScheduling();
    /// Drops back to the test task's own priority, letting the others run.
    void release();

private:
    uint8_t savedPriority_;
    bool held_;
};

/// Creates a task with the given priority and the shared test defaults.
dcos::ObjectId spawn(const char* name, uint8_t priority, dcos::TaskEntry entry, uintptr_t argument = 0,
                     bool timeSlicing = false, bool floatingPoint = false);

/// The event test tasks post to the test task when they finish.
constexpr uint32_t kDoneEvent = 1u << 30;

/// The test task's id, for tasks that report back: the task that runs the
/// tests, set by the runner (runTargetTest), by default the console's shell.
dcos::ObjectId testTask();
void setTestTask(dcos::ObjectId task);

/// Called by a test task as it finishes: counts it and wakes the test task.
void finished();

/// Waits until count tasks have called finished() since the last wait, with
/// a time-out for each; returns false if they did not.
bool waitForDone(shell::Shell& shell, unsigned count, uint64_t timeoutNs = 2000000000ull);

/// Busy-waits (without blocking) for ns of uptime.
void spin(uint64_t ns);

/// Prints a failed check with its line and returns false.
bool check(shell::Shell& shell, bool condition, const char* what);

/// Compares a status and prints both on mismatch.
bool checkStatus(shell::Shell& shell, dcos::Status actual, dcos::Status expected, const char* what);

/// An object id typed on the console (a number, 0x for hexadecimal); false
/// for text that is not one or does not fit 32 bits.
bool parseObjectId(const char* text, dcos::ObjectId& id);

} // namespace target_test
