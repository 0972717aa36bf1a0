// The semaphore agent's kernel side, as other kernel parts and the benchmarks see it.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>

namespace dcos::internal {

/// Semaphores that exist on this node, the kernel's own included (the
/// console's shell-life semaphore). Cost O(1).
size_t semaphoreCount();

/// Whether the local semaphore @p id is binary, or why the id names none.
/// The remote agent asks before it serves an Acquire or Release: a binary
/// semaphore is held by a task, and its holder cannot be a task of another
/// node yet. O(1).
Result<bool> isBinarySemaphore(ObjectId id);

/// A semaphore named @p name visible from @p askingScope.
Result<ObjectId> semaphoreNameToObject(const char* name, Visibility askingScope);

} // namespace dcos::internal
