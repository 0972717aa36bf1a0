// Priority-sorted wait list of the blocking primitives (semaphores, ports, events).
#pragma once

#include <dcos/internal/SortedList.hpp>

#include <stdint.h>

namespace dcos::internal {

/// Links a task embeds, by deriving from it, to wait on a WaitList.
template <typename Tag = void>
using WaitListNode = SortedListNode<uint8_t, Tag>;

/// Tasks waiting for a resource, highest static priority (0) first, FIFO among equals.
///
/// The key is the waiter's static priority 0..31. Because the waiter's own
/// task object carries the links, blocking never allocates. A wait list is a
/// SortedList with a priority key; see there for the cost of each operation.
template <typename T, typename Tag = void>
using WaitList = SortedList<T, uint8_t, Tag>;

} // namespace dcos::internal
