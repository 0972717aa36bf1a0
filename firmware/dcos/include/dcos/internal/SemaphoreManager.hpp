// The semaphore agent's kernel side, as other kernel parts and the benchmarks see it.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/KernelConfig.hpp>

#include <stddef.h>

namespace dcos::internal {

/// Semaphores that exist on this node, the kernel's own included (the
/// console's shell-life semaphore). Cost O(1).
size_t semaphoreCount();

/// Whether the local semaphore @p id is binary, or why the id names none.
/// The remote agent asks before it serves an Acquire or Release: a binary
/// semaphore is held by a task, so another node's task asks for it with
/// the held forms, which name the task. O(1).
Result<bool> isBinarySemaphore(ObjectId id);

/// How the local semaphore @p id was created, for the system engineering
/// interface agent's ObjectInfo (a host saving a node's configuration
/// makes the same again). Bit 0 counting, bit 1 priority inheritance, bit 2
/// waiters first come first served; or why the id names none. O(1).
Result<uint32_t> semaphoreSettings(ObjectId id);

// ---- binary semaphores held by tasks of other nodes ------------------------
//
// A binary semaphore of this node may be held by a task of another node
// (docs/protocols/remote-transactions.md, "Binary semaphores"). The remote
// agent's worker acquires it as itself, then hands the hold to that task,
// which the semaphore then names as its holder: its Release, GetHolder and
// deadlock check go by the task's id. Priority inheritance does not reach
// another node (seed 7.11). Whoever waits for a semaphore so held asks the
// holder's node, every kHolderProbeNs of its wait, whether the holder still
// exists; a holder that ended or whose node is unreachable gives the
// semaphore back, and its waiters get Abandoned, as for a local holder.

/// How long a waiter for a semaphore held by another node's task waits
/// between two probes of the holder: the remote watchdog's silent time.
constexpr uint64_t kHolderProbeNs = uint64_t{kRemoteWatchdogMs} * kRemoteSilentPeriods * 1'000'000;

/// The task of another node that holds @p id; null when a task of this
/// node holds it, when it is free, or for a counting semaphore or a wrong id.
/// O(1).
ObjectId remoteHolderOf(ObjectId id);

/// Makes @p holder, a task of another node, the holder of the binary
/// semaphore @p id, which the calling task (a remote agent worker) has just
/// acquired. NotOwner when the caller does not hold it. O(1).
Status holdForRemote(ObjectId id, ObjectId holder);

/// Release of @p id by @p holder, a task of another node: the next waiter
/// gets it, or it becomes free. NotOwner when @p holder does not hold it;
/// a counting semaphore's Release. O(1).
Status releaseForRemote(ObjectId id, ObjectId holder);

/// Asks whether @p id's remote holder still exists (a remote GetState of
/// it, which blocks up to the watchdog's time) and, when it ended or its
/// node is unreachable, frees the semaphore and wakes its waiters with
/// Abandoned. True when it freed it. Called by waiters between slices.
bool probeRemoteHolder(ObjectId id);

/// Frees every binary semaphore held by a task of @p node, which has
/// started again: its tasks of before no longer run, so their holds are
/// given up as the probe gives up a gone holder's, waiters woken with
/// Abandoned. Returns how many it freed. O(active semaphores), each under
/// its own interrupt guard; called by the remote agent's receiver.
size_t freeHoldsOfNode(uint16_t node);

/// A semaphore named @p name visible from @p askingScope.
Result<ObjectId> semaphoreNameToObject(const char* name, Visibility askingScope);

} // namespace dcos::internal
