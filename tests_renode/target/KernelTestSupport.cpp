#include "KernelTestSupport.hpp"

#include <dcos/TimerAgent.hpp>

#include <arch_x86/Cpu.hpp>

namespace target_test {

namespace {
char traceText[128];
volatile size_t traceLength = 0;
dcos::ObjectId testTaskId;
volatile unsigned doneCount = 0;
} // namespace

void finished()
{
    {
        arch_x86::InterruptGuard guard;
        doneCount = doneCount + 1;
    }
    (void)dcos::taskAgent.PostEvent(testTask(), kDoneEvent);
}

void Trace::clear()
{
    arch_x86::InterruptGuard guard;
    traceLength = 0;
    traceText[0] = '\0';
}

void Trace::record(char mark)
{
    arch_x86::InterruptGuard guard;
    if (traceLength + 1 < sizeof traceText) {
        traceText[traceLength] = mark;
        traceLength = traceLength + 1;
        traceText[traceLength] = '\0';
    }
}

const char* Trace::text() { return traceText; }

bool Trace::expect(shell::Shell& shell, const char* expected)
{
    const char* actual = text();
    size_t i = 0;
    while (expected[i] != '\0' && actual[i] == expected[i]) {
        ++i;
    }
    const bool same = expected[i] == '\0' && actual[i] == '\0';
    shell.print("trace \"%s\", expected \"%s\": %s\r\n", actual, expected, same ? "same" : "DIFFERENT");
    return same;
}

HoldScheduling::HoldScheduling() : held_(true)
{
    savedPriority_ = dcos::taskAgent.GetPriority(testTask()).value();
    (void)dcos::taskAgent.ChangePriority(testTask(), 0);
}

HoldScheduling::~HoldScheduling() { release(); }

void HoldScheduling::release()
{
    if (held_) {
        held_ = false;
        (void)dcos::taskAgent.ChangePriority(testTask(), savedPriority_);
    }
}

dcos::ObjectId spawn(const char* name, uint8_t priority, dcos::TaskEntry entry, uintptr_t argument, bool timeSlicing,
                     bool floatingPoint)
{
    dcos::TaskAttributes attributes;
    attributes.name = name;
    attributes.priority = priority;
    attributes.stackSize = 4096;
    attributes.timeSlicing = timeSlicing;
    attributes.floatingPoint = floatingPoint;
    const dcos::Result<dcos::ObjectId> id = dcos::taskAgent.Create(attributes, entry, argument);
    return id.ok() ? id.value() : dcos::ObjectId::null();
}

void setTestTask(dcos::ObjectId task) { testTaskId = task; }

dcos::ObjectId testTask()
{
    // The tests run in the console's shell task unless the runner said otherwise.
    if (testTaskId.isNull()) {
        testTaskId = dcos::taskAgent.NameToObject("shell").value();
    }
    return testTaskId;
}

bool waitForDone(shell::Shell& shell, unsigned count, uint64_t timeoutNs)
{
    // Events are not queued, so tasks finishing together post one event;
    // the count says how many really finished.
    while (doneCount < count) {
        const dcos::Result<uint32_t> events = dcos::taskAgent.ReceiveEvent(kDoneEvent, dcos::EventWait::Any, timeoutNs);
        if (!events.ok() && doneCount < count) {
            shell.print("only %u of %u tasks finished: %s\r\n", doneCount, count, dcos::statusName(events.status()));
            doneCount = 0;
            return false;
        }
    }
    arch_x86::InterruptGuard guard;
    doneCount = doneCount - count;
    return true;
}

void spin(uint64_t ns)
{
    const uint64_t end = dcos::timerAgent.Uptime() + ns;
    while (dcos::timerAgent.Uptime() < end) {
    }
}

bool check(shell::Shell& shell, bool condition, const char* what)
{
    if (!condition) {
        shell.print("check failed: %s\r\n", what);
    }
    return condition;
}

bool checkStatus(shell::Shell& shell, dcos::Status actual, dcos::Status expected, const char* what)
{
    if (actual != expected) {
        shell.print("check failed: %s: got '%s', expected '%s'\r\n", what, dcos::statusName(actual),
                    dcos::statusName(expected));
        return false;
    }
    return true;
}

bool parseObjectId(const char* text, dcos::ObjectId& id)
{
    unsigned long raw;
    if (!shell::Shell::parseUnsigned(text, raw) || raw > 0xFFFFFFFFul) {
        return false;
    }
    id = dcos::ObjectId::fromRaw(static_cast<uint32_t>(raw));
    return true;
}

} // namespace target_test
