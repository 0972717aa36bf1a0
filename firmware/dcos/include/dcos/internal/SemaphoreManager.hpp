// The semaphore agent's kernel side, as other kernel parts and the benchmarks see it.
#pragma once

#include <stddef.h>

namespace dcos::internal {

/// Semaphores that exist on this node, the kernel's own included (the
/// console's shell-life semaphore). Cost O(1).
size_t semaphoreCount();

} // namespace dcos::internal
