// What the buffer pool and segmented heap agents share (seed 7.7, 7.8).
//
// Both agents manage application-supplied memory areas in an object table
// and record a holder for every buffer or segment handed out; their
// configuration services and the holder rules are the same, so both call
// these instead of keeping a copy each. The area type (BufferPool or
// SegmentedHeap) provides kSystemHolder and transfer(); the agent supplies
// its table, its lazy start and its id lookup.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/HeldList.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TaskManager.hpp>

#include <arch_x86/Cpu.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal::memory_area {

/// The holder tag of the task @p task: the low half of its id, its type and
/// index. The fast paths shift it into the high half of a state word or
/// header, and the whole id's low half is that shift alone, where the index
/// would need a mask first. The task type is 1, so a task's tag lies in
/// [0x1000, 0x1FFF] and never meets the reserved tags at the top of the range.
[[gnu::always_inline]] inline uint16_t holderOfTask(ObjectId task) { return static_cast<uint16_t>(task.raw()); }

static_assert(static_cast<uint16_t>(ObjectId(0xFFFF, ObjectType::Task, ObjectId::kMaxIndex).raw()) < 0xFFFD,
              "a task's holder tag must differ from the system's, the free mark and the lent mark");

/// The task that holds memory the caller takes: the running task, or null
/// for the system in an interrupt handler and before the scheduler starts.
/// Inline, from the scheduler's running task (what currentTaskId() gives),
/// because Allocate and Return ask on their fast paths.
[[gnu::always_inline]] inline Task* callerTask()
{
    // Unlikely: the task's case then runs straight through, without the jump
    // over the system's that GCC would otherwise place on it. Outside task
    // context covers both of the system's cases, an interrupt handler and
    // the boot before the scheduler starts, in one test.
    if (outsideTaskContext()) [[unlikely]] {
        return nullptr;
    }
    // In task context the scheduler has started, so a task runs: telling
    // the compiler spares the callers' test of the result for null.
    Task* const task = &Scheduler::current();
    if (task == nullptr) {
        __builtin_unreachable();
    }
    return task;
}

/// The holder tag of memory held by @p task, or @p systemHolder for null (the system).
[[gnu::always_inline]] inline uint16_t holderOf(const Task* task, uint16_t systemHolder)
{
    return task != nullptr ? holderOfTask(task->id) : systemHolder;
}

/// The holder for a new owner given as a task id; the null id is the system.
inline Result<uint16_t> holderFor(ObjectId newOwner, uint16_t systemHolder)
{
    const Status status = TaskManager::checkNewOwner(newOwner);
    if (status != Status::Ok) {
        return status;
    }
    return newOwner.isNull() ? systemHolder : holderOfTask(newOwner);
}

/// NameToObject: refused in interrupt handlers; O(N) in the active slots.
template <typename Table, typename Start>
Result<ObjectId> nameToObject(Table& table, Start start, const char* name, Visibility askingScope)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    start();
    return table.NameToObject(name, askingScope);
}

/// AddObjects: a super user's configuration service, not in interrupt handlers.
template <typename Table, typename Start>
Status addObjects(Table& table, Start start, size_t count)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    start();
    return table.AddObjects(count);
}

/// XferOwnership of the pool or heap itself: its owner or a super user may
/// hand it to a live task or to the system.
template <typename Table, typename Lookup>
Status transferObject(Table& table, Lookup lookup, ObjectId id, ObjectId newOwner, uint16_t systemHolder)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    const auto object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    const Status owner = table.checkOwnerOrPrivileged(id, currentTaskId(), currentTaskIsSuperUser());
    if (owner != Status::Ok) {
        return owner;
    }
    const Result<uint16_t> newHolder = holderFor(newOwner, systemHolder);
    if (!newHolder.ok()) {
        return newHolder.status();
    }
    return table.XferOwnership(id, table.ownerOf(id).value(), newOwner);
}

/// Moves a held item's links after its holder changed: off the list of
/// @p from (null when the system held it) and onto the list of @p to (null
/// for the system, whose items are on no list). @p list selects the task's
/// list of buffers or of segments; @p take and @p give are the agent's
/// HeldList::take and give with its resolver. O(1).
inline void moveHeld(HeldHead Task::*list, Task* from, Task* to, uint32_t handle, uint8_t* links,
                     void (*take)(HeldHead&, uint32_t), void (*give)(HeldHead&, uint32_t, uint8_t*))
{
    if (from != nullptr) {
        give(from->*list, handle, links);
    }
    if (to != nullptr) {
        take(to->*list, handle);
    }
}

/// Gives back everything a dead task held of one kind (@p list: its buffers
/// or its segments) and empties its head: each item from the list with
/// @p reclaimOne(handle), which frees it if the task's holder tag holds it
/// and says whether it did; when the list was lost or an item fails that
/// check, with @p walkAll(), which frees every item of the kind the tag
/// holds, counted in @p walks. Returns the number of items given back.
/// @p task is null when the dead task no longer resolves: then the walk.
template <typename Resolve, typename ReclaimOne, typename WalkAll>
size_t reclaimHeld(Task* task, HeldHead Task::*list, Resolve resolve, ReclaimOne reclaimOne, WalkAll walkAll,
                   uint32_t& walks)
{
    size_t reclaimed = 0;
    const bool complete = task != nullptr
        && HeldList::forEachHeld(task->*list, resolve, [&reclaimed, reclaimOne](uint32_t handle, uint8_t*) {
               if (!reclaimOne(handle)) {
                   return false; // Not the task's: a damaged link.
               }
               ++reclaimed;
               return true;
           });
    if (task != nullptr) {
        task->*list = HeldHead{kHeldEnd, kHeldEnd};
    }
    if (!complete) {
        ++walks;
        reclaimed += walkAll();
    }
    return reclaimed;
}

/// XferOwnership of one buffer or segment the caller holds; areaOf gives
/// the object's BufferPool or SegmentedHeap. On success @p relink(object,
/// item, links, from, to) moves the item between the held lists of the
/// task that held it (null: the system) and the new owner (null: the
/// system), with moveHeld().
template <typename Lookup, typename AreaOf, typename Relink>
Status transferMemory(Lookup lookup, AreaOf areaOf, ObjectId id, void* memory, ObjectId newOwner,
                      uint16_t systemHolder, Relink relink)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    Task* const from = callerTask();
    const uint16_t holder = holderOf(from, systemHolder);
    arch_x86::InterruptGuard guard;
    const auto object = lookup(id);
    if (!object.ok()) {
        return object.status();
    }
    const Result<uint16_t> newHolder = holderFor(newOwner, systemHolder);
    if (!newHolder.ok()) {
        return newHolder.status();
    }
    Task* const to = newOwner.isNull() ? nullptr : TaskManager::resolve(newOwner).value(); // Checked by holderFor.
    auto* const area = object.value();
    return areaOf(area).transfer(
        memory, holder, newHolder.value(), [&](uint32_t item, uint8_t* links, uint16_t previousHolder) {
            relink(area, item, links, previousHolder == systemHolder ? nullptr : from, to);
        });
}

} // namespace dcos::internal::memory_area
