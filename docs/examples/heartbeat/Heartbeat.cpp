// heartbeat: one application on both nodes of the dual-Pentium board.
//
// Node 3 beats: every 100 ms it releases a counting semaphore of node 2's,
// which it found by name over the board's shared-memory network. Node 2
// watches: it creates that semaphore with global visibility and takes one
// unit per beat, counting the beats and the watches that ended without one.
//
// Both nodes run this code: node 2's image carries node 3's, linked from
// the same objects (BOARD=p5smp), and each node's loader starts the same
// declared task. The task tells the nodes apart by the node id
// (bsp::nodeId(), 2 and 3 by default) and takes that node's part.
#if !defined(DCOS_BOARD_P5SMP)
#error "heartbeat runs on the dual-Pentium board's two nodes: build it with BOARD=p5smp"
#endif

#include <bsp/Board.hpp>
#include <dcos/Application.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <runtime/Format.hpp>
#include <runtime/Text.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace heartbeat {

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

constexpr uint16_t kWatcherNode = 2; // the first processor's node
constexpr uint16_t kBeaterNode = 3;  // the second processor's
constexpr const char* kSemaphoreName = "heartbeat";
constexpr uint64_t kPeriodNs = 100'000'000;   // a beat every 100 ms
constexpr uint64_t kWatchNs = 3 * kPeriodNs;  // a watch this long without a beat is a miss
constexpr uint32_t kBeatEvent = 1u << 0;
// A lookup nobody answers takes about 200 ms: 50 of them give node 2 some
// 10 s to create its semaphore before node 3 gives up.
constexpr uint32_t kLookups = 50;

enum class Part : uint8_t { Starting, Watcher, Looking, Beater, None, Stopped };

// What the task did, for the console command. The task counts in its own
// variables and stores each count here whole; the command reads whole
// 32-bit words, which the processor reads at once.
volatile Part part = Part::Starting;
volatile uint32_t semaphoreRaw; // the semaphore's id (node 2's on both nodes)
volatile uint32_t lookups;      // node 3: NameToObject calls so far
volatile uint32_t beats;        // node 2: units taken; node 3: units released
volatile uint32_t missed;       // node 2: watches that ended without a beat, after the first
volatile uint32_t failed;       // node 3: releases that failed
const char* volatile stopReason = "";
volatile Status stopStatus = Status::Ok;

void stop(const char* why, Status status)
{
    stopReason = why;
    stopStatus = status;
    part = Part::Stopped;
    runtime::format(bsp::console(), "heartbeat: node %u stopped: %s: %s\r\n", unsigned(bsp::nodeId()), why,
                    dcos::statusName(status));
}

// Node 2: creates the semaphore every beat releases, and takes the beats.
void watch()
{
    dcos::SemaphoreAttributes attributes;
    attributes.name = kSemaphoreName;
    attributes.kind = dcos::SemaphoreKind::Counting;
    attributes.initialCount = 0;
    attributes.visibility = dcos::Visibility::Global; // node 3 finds it by name
    const Result<ObjectId> created = dcos::semaphoreAgent.Create(attributes);
    if (!created.ok()) {
        return stop("cannot create the semaphore", created.status());
    }
    semaphoreRaw = created.value().raw();
    part = Part::Watcher;
    runtime::format(bsp::console(), "heartbeat: node %u watches its semaphore '%s' (0x%08lx)\r\n",
                    unsigned(bsp::nodeId()), kSemaphoreName, static_cast<unsigned long>(semaphoreRaw));
    uint32_t heard = 0;
    uint32_t silent = 0;
    for (;;) {
        const Status taken = dcos::semaphoreAgent.Acquire(created.value(), kWatchNs);
        if (taken == Status::Ok) {
            beats = ++heard;
            if (heard == 1) {
                runtime::format(bsp::console(), "heartbeat: node %u heard the first beat\r\n",
                                unsigned(bsp::nodeId()));
            }
        } else if (taken == Status::Timeout) {
            if (heard != 0) {
                missed = ++silent; // Before the first beat node 3 is still starting.
            }
        } else {
            return stop("waiting for a beat", taken);
        }
    }
}

// Node 3: finds node 2's semaphore by name, then releases it every period.
void beat()
{
    part = Part::Looking;
    Result<ObjectId> found = Status::NotFound;
    for (uint32_t asked = 1; asked <= kLookups; ++asked) {
        lookups = asked;
        // Its own node first (it has no semaphore of that name), then the
        // other nodes over the shared-memory network.
        found = dcos::semaphoreAgent.NameToObject(kSemaphoreName);
        if (found.ok() || found.status() != Status::NotFound) {
            break;
        }
        // Not created yet: node 2 may still be starting. A sleep cut short
        // by a signal only makes the next lookup come sooner.
        (void)dcos::taskAgent.SleepFor(kPeriodNs);
    }
    if (!found.ok()) {
        return stop("cannot find node 2's semaphore", found.status());
    }
    const ObjectId semaphore = found.value();
    semaphoreRaw = semaphore.raw();
    // A periodic alarm: the beats keep their schedule however long each release takes.
    const Result<ObjectId> timer = dcos::timerAgent.Create("heartbeat", dcos::Visibility::Local);
    if (!timer.ok()) {
        return stop("no timer for the beat", timer.status());
    }
    const Status started =
        dcos::timerAgent.SetPeriodicAlarm(timer.value(), kPeriodNs, dcos::AlarmNotification::event(kBeatEvent));
    if (started != Status::Ok) {
        return stop("cannot start the beat", started);
    }
    part = Part::Beater;
    runtime::format(bsp::console(), "heartbeat: node %u beats node %u's semaphore '%s' (0x%08lx) every %lu ms\r\n",
                    unsigned(bsp::nodeId()), unsigned(semaphore.node()), kSemaphoreName,
                    static_cast<unsigned long>(semaphoreRaw), static_cast<unsigned long>(kPeriodNs / 1'000'000));
    uint32_t sent = 0;
    uint32_t refused = 0;
    for (;;) {
        const Result<uint32_t> woken =
            dcos::taskAgent.ReceiveEvent(kBeatEvent, dcos::EventWait::Any, dcos::kWaitForever);
        if (!woken.ok()) {
            return stop("waiting for the beat's alarm", woken.status());
        }
        // A remote transaction: node 2's semaphore agent performs it and answers.
        if (dcos::semaphoreAgent.Release(semaphore) == Status::Ok) {
            beats = ++sent;
        } else {
            failed = ++refused;
        }
    }
}

void heart(uintptr_t)
{
    switch (bsp::nodeId()) {
    case kWatcherNode:
        return watch();
    case kBeaterNode:
        return beat();
    default:
        part = Part::None;
        runtime::format(bsp::console(), "heartbeat: node %u has no part (node %u watches, node %u beats)\r\n",
                        unsigned(bsp::nodeId()), unsigned(kWatcherNode), unsigned(kBeaterNode));
    }
}

shell::CommandResult heartbeatCommand(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const unsigned node = bsp::nodeId();
    switch (part) {
    case Part::Starting:
        shell.print("heartbeat: node %u is starting\r\n", node);
        break;
    case Part::Watcher:
        shell.print("heartbeat: node %u watches semaphore 0x%08lx: %lu beats, %lu missed\r\n", node,
                    static_cast<unsigned long>(semaphoreRaw), static_cast<unsigned long>(beats),
                    static_cast<unsigned long>(missed));
        break;
    case Part::Looking:
        shell.print("heartbeat: node %u is looking for semaphore '%s': %lu lookups\r\n", node, kSemaphoreName,
                    static_cast<unsigned long>(lookups));
        break;
    case Part::Beater:
        shell.print("heartbeat: node %u beats semaphore 0x%08lx: %lu sent, %lu failed, %lu lookups\r\n", node,
                    static_cast<unsigned long>(semaphoreRaw), static_cast<unsigned long>(beats),
                    static_cast<unsigned long>(failed), static_cast<unsigned long>(lookups));
        break;
    case Part::None:
        shell.print("heartbeat: node %u has no part\r\n", node);
        break;
    case Part::Stopped:
        shell.print("heartbeat: node %u stopped: %s: %s\r\n", node, stopReason, dcos::statusName(stopStatus));
        break;
    }
    return shell::CommandResult::Ok;
}

constexpr dcos::app::TaskDeclaration kTasks[] = {
    {.name = "heart", .entry = heart, .priority = 10, .stackSize = 4096},
};

} // namespace

} // namespace heartbeat

DCOS_SHELL_COMMAND(heartbeatShellCommand, "heartbeat", "this node's part of the heartbeat and its counts",
                   "heartbeat", heartbeat::heartbeatCommand);

DCOS_APPLICATION(heartbeatApplication, {.name = "heartbeat", .tasks = heartbeat::kTasks});
