// The semaphore agent's application interface (seed 7.11).
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

enum class SemaphoreKind : uint8_t {
    Binary,   ///< Held by one task at a time; only the holder releases it.
    Counting, ///< A count of units; any task releases.
};

/// How waiters are served.
enum class WaitOrder : uint8_t {
    Priority, ///< Most urgent waiter first, first come first served among equals.
    Fifo,     ///< First come first served.
};

struct SemaphoreAttributes {
    const char* name = nullptr;
    SemaphoreKind kind = SemaphoreKind::Binary;
    /// Units available at creation: 0 or 1 for a binary semaphore.
    uint32_t initialCount = 1;
    /// The most units a counting semaphore may hold.
    uint32_t maximumCount = 0xFFFFFFFF;
    /// Binary semaphores only: the holder runs at the priority of its most
    /// urgent waiter, across every semaphore it holds.
    bool priorityInheritance = false;
    WaitOrder order = WaitOrder::Priority;
    Visibility visibility = Visibility::Local;
};

/// The semaphore agent interface object.
class SemaphoreAgent {
public:
    static Result<ObjectId> Create(const SemaphoreAttributes& attributes);
    /// Deletes a semaphore; every waiter wakes with Status::Deleted.
    static Status Delete(ObjectId semaphore);
    /// Takes a unit: at once, polling (kPoll gives WouldBlock), or waiting
    /// with a time-out. A binary semaphore's holder asking again gets
    /// Status::Deadlock instead of waiting for itself. A wait ends with
    /// Deleted if the semaphore is deleted, Abandoned if its holder ends.
    static Status Acquire(ObjectId semaphore, uint64_t timeout);
    /// Gives a unit back. A binary semaphore passes straight to its first
    /// waiter; only the holder may release it (NotOwner).
    static Status Release(ObjectId semaphore);
    /// Units available now.
    static Result<uint32_t> GetCount(ObjectId semaphore);
    /// The task holding a binary semaphore (null when free).
    static Result<ObjectId> GetHolder(ObjectId semaphore);
    static Result<ObjectId> NameToObject(const char* name);
    static Status XferOwnership(ObjectId semaphore, ObjectId newOwner);
    static Status AddObjects(size_t count);
};

inline constexpr SemaphoreAgent semaphoreAgent{};

} // namespace dcos
