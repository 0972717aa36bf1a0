// What an agent needs to know about the caller of a service.
//
// Every agent checks privileges, ownership and context the same way, so the
// questions are answered in one place (the task agent implements them). Host
// unit tests of an agent supply their own definitions to play any caller.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/internal/KernelConfig.hpp>

#ifndef DCOS_HOST_BUILD
#include <arch_x86/Idt.hpp>
#endif

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// The id of the task on whose behalf the current service runs. Inside an
/// interrupt handler it is the interrupted task.
ObjectId currentTaskId();

/// True when the calling task has super-user privilege (seed 6.4, layer 2).
/// Privileged services (Create and Delete of devices, InstallISR, the legal
/// interrupt limit, SetSystemClock, the time-slice quantum) check it.
bool currentTaskIsSuperUser();

/// True while an interrupt handler runs. Blocking services refuse to run
/// there with Status::InInterrupt. On the board it is inline, one load of
/// the nesting depth, because the real-time services ask on their fast path.
#ifdef DCOS_HOST_BUILD
bool inInterruptContext();
#else
inline bool inInterruptContext() { return arch_x86::Idt::nestingDepth() != 0; }
#endif

/// True when the caller is the system rather than a task: inside an
/// interrupt handler, or at boot before the scheduler runs its first task.
/// On the board it is one test of one word (Idt::outsideTaskContext), for
/// the fast paths that record the calling task as a holder.
#ifdef DCOS_HOST_BUILD
bool outsideTaskContext();
#else
inline bool outsideTaskContext() { return arch_x86::Idt::outsideTaskContext(); }
#endif

/// The node id of this controller, stamped into every object id it issues.
uint16_t localNode();

/// The slot a task id names in the task table, below kTaskCapacity for any
/// task id (for a stale or remote one, the slot its index last named).
size_t taskSlotOf(ObjectId task);

/// The owner keys of the kernel's object tables (see ObjectTable.hpp): a
/// task's slot, so that each table keeps one owner list per task slot, a
/// few hundred bytes, rather than one per 12-bit index.
struct TaskOwnerKeys {
    static constexpr size_t kCount = kTaskCapacity;
    static size_t keyOf(ObjectId owner) { return taskSlotOf(owner); }
};

} // namespace dcos::internal
