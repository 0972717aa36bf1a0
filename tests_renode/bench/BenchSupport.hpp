// Populations of kernel objects for the agent benchmarks (bench image only).
//
// Every agent benchmark measures one call on one object while a given number
// of objects of its type exist. These helpers create that population through
// the agents' own primitives, grow the tables with AddObjects in groups of
// eight when they are full (the bench image is built with 4096-slot tables,
// mk/bench.mk), and remove it again in teardown, so that every object count
// starts from the same state.
//
// Tasks: the count is every task in the system, the idle and shell tasks and
// a benchmark's partner tasks included, so "4096 tasks" fills the table.
#pragma once

#include "Benchmark.hpp"

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/TaskAgent.hpp>

#include <stddef.h>
#include <stdint.h>

namespace bench {

/// An event no one ever posts: filler tasks wait for it for ever.
constexpr uint32_t kNeverPostedEvent = 1u << 31;

/// The priority of filler tasks that block at once: above the shell (24),
/// so each runs as soon as it is created and is blocked when Create returns.
constexpr uint8_t kBlockedFillerPriority = 20;
/// The priority of filler tasks that stay ready: below the shell, so they
/// never run while a benchmark does.
constexpr uint8_t kReadyFillerPriority = 30;

/// The entry of a filler task: waits for kNeverPostedEvent for ever.
void blockForever(uintptr_t);

/// Creates a task with a kMinimumStackSize stack, growing the task table by
/// eight slots when it is full, and remembers it for killTasks(). A task of
/// higher priority than the caller runs before this returns.
dcos::Result<dcos::ObjectId> spawnTask(dcos::TaskEntry entry, uint8_t priority, uintptr_t argument = 0,
                                       const char* name = nullptr, bool floatingPoint = false);

/// Calls create() and, when its table is full, grows the table by eight
/// slots with addObjects(8) and calls create() once more: how a population
/// reaches 4096 objects in tables that start small.
template <typename Create, typename AddObjects>
dcos::Result<dcos::ObjectId> createGrowing(Create create, AddObjects addObjects)
{
    dcos::Result<dcos::ObjectId> id = create();
    if (id.status() == dcos::Status::TableFull) {
        const dcos::Status grown = addObjects(8);
        if (grown != dcos::Status::Ok) {
            return grown;
        }
        id = create();
    }
    return id;
}

/// Adds filler tasks running blockForever until total tasks exist. The last
/// one is named "target" and its id returned in target (null when none was
/// added).
dcos::Status fillTasks(uint32_t total, uint8_t priority, dcos::ObjectId* target = nullptr);

/// Kills every task spawnTask created that is still alive, newest first.
void killTasks();

/// Forgets a task spawnTask created that has since ended by itself.
void forgetTask(dcos::ObjectId task);

/// The number of tasks in the system.
uint32_t taskCount();

/// The calling (shell) task's id and static priority.
dcos::ObjectId self();
uint8_t selfPriority();

} // namespace bench
