// The frequency multiplier's function blocks as DCOS tasks (seed 9.4.1,
// Fig. 9.5), joined by message ports the way the seed's blocks are joined
// by event connections:
//
//     E_CYCLE --S/R----------------> E_SR (A) --+
//        |                                       +--> XOR --A,B,Y--> DO --word--> CHECKER
//        +--START--> E_DELAY --S/R--> E_RS (B) --+
//
// - E_CYCLE (task e_cycle) goes off every half period of the source, on a
//   periodic alarm of a whole number of ticks, and alternately sets and
//   resets the bistable of wave A. It also starts E_DELAY with the same
//   set or reset, and applies new settings from the console.
// - E_DELAY (task e_delay) passes each set or reset on to the bistable of
//   wave B a fixed number of ticks later: the phase shift.
// - E_SR and E_RS (tasks e_sr, e_rs) are the set-dominant and the
//   reset-dominant bistables that hold A and B, and report each change.
// - XOR (task xor) combines them into Y and forwards A, B and Y together,
//   so that DO writes the three outputs in one DO write and no instant
//   ever shows Y disagreeing with A and B.
// - DO (task do) owns the I/O board and writes DO0 = A, DO1 = B, DO2 = Y.
// - CHECKER (task checker) reads the outputs back at the digital inputs
//   (the board wires DO to DI), checks DI(Y) == DI(A) XOR DI(B) and the
//   loopback, and counts edges.
//
// Each block is more urgent than the block that feeds it. A message sent
// to a more urgent block that waits for it runs that block at once, so an
// edge travels from the tick to the DO register in one burst, before
// anything less urgent runs, and no port ever queues more than one message.
#include "FreqMul.hpp"

#include <bsp/Board.hpp>
#include <dcos/Application.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <iobus/MfioBoard.hpp>
#include <iobus/MfioClient.hpp>
#include <runtime/Format.hpp>

namespace freqmul {

namespace {

using dcos::Message;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

// Stored by the application loader before any task runs.
ObjectId cyclePort;   // E_CYCLE's control port: new settings from the console.
ObjectId delayPort;   // E_DELAY's START input.
ObjectId setResetA;   // E_SR's S and R inputs.
ObjectId setResetB;   // E_RS's S and R inputs.
ObjectId xorPort;     // XOR's two inputs.
ObjectId outputPort;  // DO's A, B and Y inputs.
ObjectId checkerPort; // The words DO wrote.
ObjectId cycleTask;
ObjectId delayTask;
ObjectId stateLock;

// Event flags. Alarms post events, not messages, so a block that waits for
// an alarm and for something else waits for events.
constexpr uint32_t kAlarmEvent = 1u << 0;
constexpr uint32_t kControlEvent = 1u << 1; // E_CYCLE: a control message waits in its port.
constexpr uint32_t kStopEvent = 1u << 2;    // E_DELAY: drop the event being delayed.

// A lock wait longer than this means something is badly wrong; no one
// holds the lock for more than a few copies.
constexpr uint64_t kLockTimeoutNs = 100000000;

SharedState shared;

// The DO block's board, installed by the DO task (a super user).
iobus::MfioBoard board("freqmul", 0x300, 5);
// Written by the DO task before it sends anything to the checker, so the
// checker always sees it set.
ObjectId boardId;

// Runs @p update on the shared state under the lock. An update that cannot
// take the lock is dropped: the console then shows older counts, but no
// block ever waits for the console.
template <class Update>
void updateShared(Update update)
{
    if (dcos::semaphoreAgent.Acquire(stateLock, kLockTimeoutNs) == Status::Ok) {
        update(shared);
        (void)dcos::semaphoreAgent.Release(stateLock); // Cannot fail: this task holds it.
    }
}

void report(const char* block, const char* what, Status status)
{
    runtime::format(bsp::console(), "freqmul: %s cannot %s: %s\r\n", block, what, dcos::statusName(status));
}

// Blocks send to more urgent blocks that wait for them, so a Send only
// fails when an object is gone. The first failure is reported; the block
// goes on either way, since stopping would not bring the object back.
void send(const char* block, ObjectId port, const Message& message)
{
    static bool reported = false;
    const Status sent = dcos::messagePortAgent.Send(port, message, dcos::kMostUrgentMessage);
    if (sent != Status::Ok && !reported) {
        reported = true;
        report(block, "send an event", sent);
    }
}

// The S and R inputs of a bistable, as one message.
Message setReset(bool set, bool reset) { return makeMessage(set ? 1 : 0, reset ? 1 : 0); }

// ---- E_CYCLE ----------------------------------------------------------------------

struct Cycle {
    ObjectId timer;
    WaveSettings settings;
    bool levelA = false;
};

// Stops the running waves and starts new ones from A low and B low; the
// first edge comes one half period later.
void applySettings(Cycle& cycle, const WaveSettings& settings)
{
    (void)dcos::timerAgent.CancelAlarm(cycle.timer); // InvalidArgument when none was set: nothing to stop.
    // An alarm that went off before the cancel belongs to the old waves.
    (void)dcos::taskAgent.ReceiveEvent(kAlarmEvent, dcos::EventWait::Any, dcos::kPoll);
    (void)dcos::taskAgent.PostEvent(delayTask, kStopEvent);
    send("e_cycle", setResetA, setReset(false, true));
    send("e_cycle", setResetB, setReset(false, true));
    cycle.levelA = false;
    cycle.settings = settings;
    // The period is a whole number of tick periods as the timer agent
    // counts them, so every due time falls exactly on a tick: no jitter
    // from rounding, and no drift.
    const uint64_t periodNs = uint64_t{settings.halfPeriodTicks} * bsp::tickPeriodNanoseconds();
    const Status started =
        dcos::timerAgent.SetPeriodicAlarm(cycle.timer, periodNs, dcos::AlarmNotification::event(kAlarmEvent));
    if (started != Status::Ok) {
        report("e_cycle", "start its period", started);
    }
    updateShared([&](SharedState& state) {
        state.applied = settings;
        ++state.generation;
    });
}

void takeControlMessages(Cycle& cycle)
{
    Message message;
    while (dcos::messagePortAgent.Receive(cyclePort, message, dcos::kPoll) == Status::Ok) {
        // Any task may send here, so the settings are checked again.
        const SettingsCheck check = checkSettings(bsp::tickRateHz(), messageWord(message, 0), messageWord(message, 1));
        if (check.error == SettingsError::None) {
            applySettings(cycle, check.settings);
        } else {
            updateShared([](SharedState& state) { ++state.rejected; });
        }
    }
}

void cycleEntry(uintptr_t)
{
    Cycle cycle;
    const Result<ObjectId> timer = dcos::timerAgent.Create("e_cycle.period", dcos::Visibility::Local);
    if (!timer.ok()) {
        report("e_cycle", "create its timer", timer.status());
        return;
    }
    cycle.timer = timer.value();
    const SettingsCheck boot = checkSettings(bsp::tickRateHz(), kDefaultFrequencyHz, kDefaultShiftDegrees);
    if (boot.error == SettingsError::None) {
        applySettings(cycle, boot.settings);
    } else {
        // Only a tick_hz= on the command line gets here.
        runtime::format(bsp::console(), "freqmul: the %lu Hz tick cannot make the default waves; use 'freqmul set'\r\n",
                        static_cast<unsigned long>(bsp::tickRateHz()));
    }
    for (;;) {
        const Result<uint32_t> events =
            dcos::taskAgent.ReceiveEvent(kAlarmEvent | kControlEvent, dcos::EventWait::Any, dcos::kWaitForever);
        if (!events.ok()) {
            continue;
        }
        if ((events.value() & kControlEvent) != 0) {
            // An alarm received with the control event is from the waves
            // the new settings replace.
            takeControlMessages(cycle);
            continue;
        }
        cycle.levelA = !cycle.levelA;
        // A first: its edge should be as close to the tick as B's.
        send("e_cycle", setResetA, setReset(cycle.levelA, !cycle.levelA));
        send("e_cycle", delayPort,
             makeMessage(cycle.levelA ? 1 : 0, cycle.levelA ? 0 : 1, cycle.settings.shiftTicks));
    }
}

// ---- E_DELAY ----------------------------------------------------------------------

void delayEntry(uintptr_t)
{
    const Result<ObjectId> timer = dcos::timerAgent.Create("e_delay.timer", dcos::Visibility::Local);
    if (!timer.ok()) {
        report("e_delay", "create its timer", timer.status());
        return;
    }
    const uint64_t tickNs = bsp::tickPeriodNanoseconds();
    for (;;) {
        Message start;
        if (dcos::messagePortAgent.Receive(delayPort, start, dcos::kWaitForever) != Status::Ok) {
            continue;
        }
        // A stop posted while no event was being delayed was meant for an
        // earlier one: E_CYCLE sends its next START only after the stop.
        (void)dcos::taskAgent.ReceiveEvent(kStopEvent, dcos::EventWait::Any, dcos::kPoll);
        const Message delayed = setReset(messageWord(start, 0) != 0, messageWord(start, 1) != 0);
        const uint32_t delayTicks = messageWord(start, 2);
        if (delayTicks == 0) {
            send("e_delay", setResetB, delayed);
            continue;
        }
        // START arrives in the tick E_CYCLE's alarm went off in, and a
        // watchdog alarm goes off at the first tick after its whole
        // interval has passed: set now, an interval of delayTicks - 1
        // tick periods goes off exactly delayTicks ticks after E_CYCLE's.
        const Status set = dcos::timerAgent.SetWatchDogAlarm(timer.value(), uint64_t{delayTicks - 1} * tickNs,
                                                              dcos::AlarmNotification::event(kAlarmEvent));
        if (set != Status::Ok) {
            report("e_delay", "set its alarm", set);
            continue;
        }
        const Result<uint32_t> events =
            dcos::taskAgent.ReceiveEvent(kAlarmEvent | kStopEvent, dcos::EventWait::Any, dcos::kWaitForever);
        if (!events.ok() || (events.value() & kStopEvent) != 0) {
            (void)dcos::timerAgent.CancelAlarm(timer.value());
            (void)dcos::taskAgent.ReceiveEvent(kAlarmEvent, dcos::EventWait::Any, dcos::kPoll);
            continue;
        }
        send("e_delay", setResetB, delayed);
    }
}

// ---- E_SR and E_RS ----------------------------------------------------------------

struct Bistable {
    const ObjectId* input;
    uint32_t xorInput;  // 0: A, 1: B.
    bool setDominant;   // E_SR; E_RS is reset dominant.
};

constexpr Bistable kBistables[] = {
    {&setResetA, 0, true},
    {&setResetB, 1, false},
};

void bistableEntry(uintptr_t index)
{
    const Bistable& block = kBistables[index];
    bool q = false;
    for (;;) {
        Message message;
        if (dcos::messagePortAgent.Receive(*block.input, message, dcos::kWaitForever) != Status::Ok) {
            continue;
        }
        const bool set = messageWord(message, 0) != 0;
        const bool reset = messageWord(message, 1) != 0;
        bool next = q;
        if (set && reset) {
            next = block.setDominant;
        } else if (set || reset) {
            next = set;
        }
        // The seed's bistables signal an output event only when Q changes.
        if (next != q) {
            q = next;
            send(block.setDominant ? "e_sr" : "e_rs", xorPort, makeMessage(block.xorInput, q ? 1 : 0));
        }
    }
}

// ---- XOR --------------------------------------------------------------------------

void xorEntry(uintptr_t)
{
    bool inputs[2] = {false, false};
    for (;;) {
        Message message;
        if (dcos::messagePortAgent.Receive(xorPort, message, dcos::kWaitForever) != Status::Ok) {
            continue;
        }
        inputs[messageWord(message, 0) & 1] = messageWord(message, 1) != 0;
        const bool y = inputs[0] != inputs[1];
        send("xor", outputPort, makeMessage(inputs[0] ? 1 : 0, inputs[1] ? 1 : 0, y ? 1 : 0));
    }
}

// ---- DO ---------------------------------------------------------------------------

Status installBoard()
{
    iobus::IsaConflict conflict;
    const Result<ObjectId> installed = board.install("freqmul.io", dcos::Visibility::Local, &conflict);
    if (!installed.ok()) {
        return installed.status();
    }
    const Status opened = dcos::systemAgent.Open(installed.value());
    if (opened == Status::Ok) {
        boardId = installed.value();
    }
    return opened;
}

void outputEntry(uintptr_t)
{
    const Status installed = installBoard();
    updateShared([&](SharedState& state) { state.boardStatus = static_cast<uint32_t>(installed); });
    if (installed != Status::Ok) {
        report("do", "install and open the I/O board at 0x300", installed);
    }
    uint16_t written = 0; // The board's DO after reset.
    for (;;) {
        Message message;
        if (dcos::messagePortAgent.Receive(outputPort, message, dcos::kWaitForever) != Status::Ok) {
            continue;
        }
        const uint16_t word = static_cast<uint16_t>((messageWord(message, 0) != 0 ? kBitA : 0) |
                                                    (messageWord(message, 1) != 0 ? kBitB : 0) |
                                                    (messageWord(message, 2) != 0 ? kBitY : 0));
        if (word == written) {
            continue;
        }
        const Status status = boardId.isNull()
                                  ? installed
                                  : iobus::writeWord(boardId, iobus::channel::kDigitalOutputs, word);
        if (status == Status::Ok) {
            written = word;
            send("do", checkerPort, makeMessage(word));
        }
        updateShared([&](SharedState& state) {
            ++(status == Status::Ok ? state.checker.doWrites : state.checker.doWriteErrors);
        });
    }
}

// ---- CHECKER ----------------------------------------------------------------------

void checkerEntry(uintptr_t)
{
    uint16_t previous = 0; // DI follows DO, which is 0 after reset.
    for (;;) {
        Message message;
        if (dcos::messagePortAgent.Receive(checkerPort, message, dcos::kWaitForever) != Status::Ok) {
            continue;
        }
        const uint16_t expected = static_cast<uint16_t>(messageWord(message, 0));
        const Result<uint16_t> inputs = iobus::readWord(boardId, iobus::channel::kDigitalInputs);
        if (!inputs.ok()) {
            updateShared([](SharedState& state) { ++state.checker.readErrors; });
            continue;
        }
        const uint16_t di = inputs.value() & kWaveBits;
        const bool a = (di & kBitA) != 0;
        const bool b = (di & kBitB) != 0;
        const bool y = (di & kBitY) != 0;
        const uint16_t changed = di ^ previous;
        previous = di;
        updateShared([&](SharedState& state) {
            CheckerStatistics& checker = state.checker;
            ++checker.samples;
            for (unsigned bit = 0; bit < 3; ++bit) {
                checker.edges[bit] += (changed >> bit) & 1u;
            }
            checker.xorMismatches += y != (a != b) ? 1 : 0;
            checker.loopbackMismatches += di != expected ? 1 : 0;
        });
    }
}

// ---- The application --------------------------------------------------------------

// Most urgent at the end of the chain (see the top of this file); every
// block is more urgent than the console (24).
constexpr dcos::app::TaskDeclaration kTasks[] = {
    {.name = "checker", .entry = checkerEntry, .priority = 4},
    {.name = "do", .entry = outputEntry, .priority = 5, .superUser = true},
    {.name = "xor", .entry = xorEntry, .priority = 6},
    {.name = "e_sr", .entry = bistableEntry, .priority = 7, .argument = 0},
    {.name = "e_rs", .entry = bistableEntry, .priority = 7, .argument = 1},
    {.name = "e_delay", .entry = delayEntry, .priority = 8, .id = &delayTask},
    {.name = "e_cycle", .entry = cycleEntry, .priority = 9, .id = &cycleTask},
};

constexpr dcos::app::MessagePortDeclaration kPorts[] = {
    {.name = "e_cycle.ctl", .receiver = "e_cycle", .order = dcos::PortOrder::Fifo, .id = &cyclePort},
    {.name = "e_delay.start", .receiver = "e_delay", .order = dcos::PortOrder::Fifo, .id = &delayPort},
    {.name = "e_sr.in", .receiver = "e_sr", .order = dcos::PortOrder::Fifo, .id = &setResetA},
    {.name = "e_rs.in", .receiver = "e_rs", .order = dcos::PortOrder::Fifo, .id = &setResetB},
    {.name = "xor.in", .receiver = "xor", .order = dcos::PortOrder::Fifo, .id = &xorPort},
    {.name = "do.in", .receiver = "do", .order = dcos::PortOrder::Fifo, .id = &outputPort},
    {.name = "checker.in", .receiver = "checker", .order = dcos::PortOrder::Fifo, .id = &checkerPort},
};

// Priority inheritance: the console, less urgent than every block, holds
// the lock while it copies the state.
constexpr dcos::app::SemaphoreDeclaration kSemaphores[] = {
    {.name = "freqmul.lock", .priorityInheritance = true, .id = &stateLock},
};

} // namespace

bool readSharedState(SharedState& copy)
{
    if (dcos::semaphoreAgent.Acquire(stateLock, kLockTimeoutNs) != Status::Ok) {
        return false;
    }
    copy = shared;
    (void)dcos::semaphoreAgent.Release(stateLock); // Cannot fail: this task holds it.
    return true;
}

Status requestSettings(uint32_t frequencyHz, uint32_t shiftDegrees)
{
    SharedState before;
    if (!readSharedState(before)) {
        return Status::Timeout;
    }
    const Status sent = dcos::messagePortAgent.Send(cyclePort, makeMessage(frequencyHz, shiftDegrees), 0);
    if (sent != Status::Ok) {
        return sent;
    }
    const Status posted = dcos::taskAgent.PostEvent(cycleTask, kControlEvent);
    if (posted != Status::Ok) {
        return posted;
    }
    // E_CYCLE is more urgent than the console, so it has taken the
    // settings already; the wait only bounds a node that is overloaded.
    for (unsigned attempt = 0; attempt < 100; ++attempt) {
        SharedState now;
        if (readSharedState(now)) {
            if (now.generation != before.generation) {
                return Status::Ok;
            }
            if (now.rejected != before.rejected) {
                return Status::InvalidArgument;
            }
        }
        (void)dcos::taskAgent.SleepFor(1000000); // A shorter wait only polls sooner.
    }
    return Status::Timeout;
}

DCOS_APPLICATION(frequencyMultiplier, {
                                          .name = "freqmul",
                                          .tasks = kTasks,
                                          .semaphores = kSemaphores,
                                          .messagePorts = kPorts,
                                          .tickRateHz = kTickRateHz,
                                      });

} // namespace freqmul
