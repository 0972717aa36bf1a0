// The minimal image's built-in self-check (build/486/dcos486-minimal.elf).
//
// The minimal kernel configuration has no console shell, so this small
// application is its proof of life: at boot it exercises each agent the
// configuration keeps (task, scheduler, timer and system) once, prints one
// line per check and then a result line,
//
//     SELFCHECK: PASS (9 checks)
//
// or "SELFCHECK: FAIL (<n> of 9 checks failed)", which the emulator suite
// waits for (tests_renode/test_minimal_kernel.py). It uses only the
// application interface, so it also shows what an application of the
// minimal kernel can do. A product replaces it with its own application
// (docs/guide/kernel-configurations.md). Every wait has a time-out, so a
// broken service fails its check instead of hanging the node.
#include <dcos/Application.hpp>
#include <dcos/Device.hpp>
#include <dcos/SchedulerAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

#include <bsp/Board.hpp>
#include <runtime/Format.hpp>

namespace {

using namespace dcos;

constexpr uint64_t kMillisecond = 1000000;
// Long enough for any check on a loaded host, short enough to fail visibly.
constexpr uint64_t kCheckTimeout = 2000 * kMillisecond;

constexpr uint8_t kSelfCheckPriority = 20;
constexpr uint32_t kReportEvent = 1u << 8;
constexpr uint32_t kAlarmEvent = 1u << 9;

ObjectId checker;
// What the helper tasks saw, in order.
char trace[16];
volatile unsigned traceLength;
volatile unsigned signalSeen;
volatile uint32_t eventsSeen;

void record(char mark)
{
    if (traceLength + 1 < sizeof trace) {
        trace[traceLength] = mark;
        traceLength = traceLength + 1;
        trace[traceLength] = '\0';
    }
}

bool traceIs(const char* expected)
{
    unsigned i = 0;
    for (; expected[i] != '\0'; ++i) {
        if (i >= traceLength || trace[i] != expected[i]) {
            return false;
        }
    }
    return i == traceLength;
}

void resetTrace()
{
    traceLength = 0;
    trace[0] = '\0';
}

// Waits for the helper's report, with a time-out.
bool reported() { return taskAgent.ReceiveEvent(kReportEvent, EventWait::Any, kCheckTimeout).ok(); }

ObjectId spawn(const char* name, uint8_t priority, TaskEntry entry, uintptr_t argument = 0)
{
    TaskAttributes attributes;
    attributes.name = name;
    attributes.priority = priority;
    attributes.stackSize = 4096;
    const Result<ObjectId> task = taskAgent.Create(attributes, entry, argument);
    return task.ok() ? task.value() : ObjectId::null();
}

void marker(uintptr_t mark) { record(static_cast<char>(mark)); }

// A more urgent task runs as soon as it is created; a less urgent one only
// when the creator blocks.
bool checkPriorities()
{
    resetTrace();
    const bool created = !spawn("urgent", 10, marker, 'U').isNull() && !spawn("lazy", 30, marker, 'L').isNull();
    const bool before = traceIs("U");
    return created && before && taskAgent.SleepFor(kMillisecond) == Status::Ok && traceIs("UL");
}

bool checkSleep()
{
    const uint64_t start = timerAgent.Uptime();
    if (taskAgent.SleepFor(10 * kMillisecond) != Status::Ok) {
        return false;
    }
    const uint64_t slept = timerAgent.Uptime() - start;
    return slept >= 10 * kMillisecond && slept < kCheckTimeout;
}

void allEventsWaiter(uintptr_t)
{
    const Result<uint32_t> events = taskAgent.ReceiveEvent(0x3, EventWait::All, kCheckTimeout);
    eventsSeen = events.ok() ? events.value() : 0;
    (void)taskAgent.PostEvent(checker, kReportEvent);
}

// A task waiting for all of two events stays blocked after the first.
bool checkEvents()
{
    eventsSeen = 0;
    const ObjectId waiter = spawn("waiter", 15, allEventsWaiter);
    if (waiter.isNull() || taskAgent.PostEvent(waiter, 0x1) != Status::Ok) {
        return false;
    }
    const Result<TaskState> state = taskAgent.GetState(waiter);
    const bool stillBlocked = state.ok() && state.value() == TaskState::Blocked;
    return stillBlocked && taskAgent.PostEvent(waiter, 0x2) == Status::Ok && reported() && eventsSeen == 0x3;
}

void onSignal(unsigned signal)
{
    signalSeen = signal;
    (void)taskAgent.PostEvent(checker, kReportEvent);
}

void signalTarget(uintptr_t)
{
    (void)taskAgent.SetSignalHandler(onSignal);
    (void)taskAgent.PostEvent(checker, kReportEvent);
    (void)taskAgent.ReceiveEvent(0x1, EventWait::Any, kCheckTimeout);
}

// A signal does not wake a blocked task: its handler runs when the task next runs.
bool checkSignals()
{
    signalSeen = 0;
    const ObjectId target = spawn("signalled", 15, signalTarget);
    bool ok = !target.isNull() && reported() && taskAgent.SendSignal(target, 5) == Status::Ok;
    ok = ok && signalSeen == 0;
    return ok && taskAgent.PostEvent(target, 0x1) == Status::Ok && reported() && signalSeen == 5;
}

void suspendedMarker(uintptr_t) { record('S'); }

bool checkSuspend()
{
    resetTrace();
    const ObjectId task = spawn("suspended", 30, suspendedMarker);
    if (task.isNull() || taskAgent.Suspend(task) != Status::Ok || taskAgent.SleepFor(kMillisecond) != Status::Ok) {
        return false;
    }
    const bool heldBack = traceIs("");
    return heldBack && taskAgent.Resume(task) == Status::Ok && taskAgent.SleepFor(kMillisecond) == Status::Ok &&
           traceIs("S");
}

bool checkWatchdogAlarm()
{
    const Result<ObjectId> timer = timerAgent.Create("selfcheck", Visibility::Local);
    if (!timer.ok()) {
        return false;
    }
    const uint64_t start = timerAgent.Uptime();
    bool ok = timerAgent.SetWatchDogAlarm(timer.value(), 5 * kMillisecond, AlarmNotification::event(kAlarmEvent)) ==
              Status::Ok;
    ok = ok && taskAgent.ReceiveEvent(kAlarmEvent, EventWait::Any, kCheckTimeout).ok();
    ok = ok && timerAgent.Uptime() - start >= 5 * kMillisecond;
    return timerAgent.Delete(timer.value()) == Status::Ok && ok;
}

bool checkPeriodicAlarm()
{
    const Result<ObjectId> timer = timerAgent.Create("periodic", Visibility::Local);
    if (!timer.ok()) {
        return false;
    }
    bool ok = timerAgent.SetPeriodicAlarm(timer.value(), 2 * kMillisecond, AlarmNotification::event(kAlarmEvent)) ==
              Status::Ok;
    for (int period = 0; ok && period < 3; ++period) {
        ok = taskAgent.ReceiveEvent(kAlarmEvent, EventWait::Any, kCheckTimeout).ok();
    }
    ok = ok && timerAgent.CancelAlarm(timer.value()) == Status::Ok;
    return timerAgent.Delete(timer.value()) == Status::Ok && ok;
}

void yielder(uintptr_t mark)
{
    for (int round = 0; round < 2; ++round) {
        record(static_cast<char>(mark));
        (void)schedulerAgent.Yield();
    }
    (void)taskAgent.PostEvent(checker, kReportEvent);
}

// Two tasks of one priority take turns with Yield.
bool checkYield()
{
    resetTrace();
    // Created while this task is the more urgent, so both are ready when they start.
    bool ok = taskAgent.ChangePriority(checker, 5) == Status::Ok;
    ok = ok && !spawn("first", 12, yielder, 'a').isNull() && !spawn("second", 12, yielder, 'b').isNull();
    ok = taskAgent.ChangePriority(checker, kSelfCheckPriority) == Status::Ok && ok;
    return ok && reported() && traceIs("abab");
}

// A driver that hands back what was written to it.
class EchoDevice final : public Device {
    Status Probe() override { return Status::Ok; }
    Result<size_t> Read(uint32_t, void* buffer, size_t length) override
    {
        const size_t count = length < held_ ? length : held_;
        for (size_t i = 0; i < count; ++i) {
            static_cast<uint8_t*>(buffer)[i] = bytes_[i];
        }
        return count;
    }
    Result<size_t> Write(uint32_t, const void* buffer, size_t length) override
    {
        held_ = length < sizeof bytes_ ? length : sizeof bytes_;
        for (size_t i = 0; i < held_; ++i) {
            bytes_[i] = static_cast<const uint8_t*>(buffer)[i];
        }
        return held_;
    }

    uint8_t bytes_[8] = {};
    size_t held_ = 0;
};

EchoDevice echo;

bool checkDevice()
{
    const Result<ObjectId> device = systemAgent.Create(echo, "echo", Visibility::Local);
    if (!device.ok()) {
        return false;
    }
    const Result<ObjectId> found = systemAgent.NameToObject("echo");
    bool ok = found.ok() && found.value() == device.value() && systemAgent.Open(device.value()) == Status::Ok;
    const uint8_t sent[3] = {0xD, 0xC, 0x5};
    uint8_t received[3] = {};
    const Result<size_t> written = systemAgent.Write(device.value(), 0, sent, sizeof sent);
    const Result<size_t> read = systemAgent.Read(device.value(), 0, received, sizeof received);
    ok = ok && written.ok() && written.value() == 3 && read.ok() && read.value() == 3 && received[0] == 0xD &&
         received[1] == 0xC && received[2] == 0x5;
    ok = ok && systemAgent.Close(device.value()) == Status::Ok;
    return systemAgent.Delete(device.value()) == Status::Ok && ok;
}

struct Check {
    const char* name;
    bool (*run)();
};

constexpr Check checks[] = {
    {"priorities and preemption", checkPriorities},
    {"sleep", checkSleep},
    {"events", checkEvents},
    {"signals", checkSignals},
    {"suspend and resume", checkSuspend},
    {"watchdog alarm", checkWatchdogAlarm},
    {"periodic alarm", checkPeriodicAlarm},
    {"yield", checkYield},
    {"device", checkDevice},
};

void selfCheck(uintptr_t)
{
    runtime::CharacterSink& console = bsp::console();
    checker = taskAgent.IdOfSelf();
    unsigned failed = 0;
    for (const Check& check : checks) {
        const bool passed = check.run();
        failed += passed ? 0 : 1;
        runtime::format(console, "selfcheck: %s: %s\r\n", check.name, passed ? "ok" : "FAILED");
    }
    const unsigned count = sizeof checks / sizeof checks[0];
    if (failed == 0) {
        runtime::format(console, "SELFCHECK: PASS (%u checks)\r\n", count);
    } else {
        runtime::format(console, "SELFCHECK: FAIL (%u of %u checks failed)\r\n", failed, count);
    }
}

constexpr app::TaskDeclaration tasks[] = {
    {.name = "selfcheck", .entry = selfCheck, .priority = kSelfCheckPriority, .stackSize = 4096, .superUser = true},
};

} // namespace

DCOS_APPLICATION(selfCheckApplication, {.name = "selfcheck", .tasks = tasks});
