// The buffers and segments this node's pools and heaps handed to tasks of
// other nodes that share its memory (the dual-Pentium board's two nodes;
// docs/protocols/remote-transactions.md, "Pools and heaps").
//
// Locally a buffer is held by the task that allocated it (seed 7.7, 7.8).
// A task of another node has no place in this node's task lists, so the
// serving node allocates such a buffer as the system's and notes here which
// node holds it: a Return from any other node is refused, and when that
// node starts again (its tasks of before are gone) everything it held is
// returned. The table is fixed in size, so a remote allocation is refused
// with Busy rather than left untracked when it is full.
//
// Not thread safe: the remote agent keeps it under its lock.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

class RemoteMemoryHolds {
public:
    /// How many buffers and segments other nodes may hold at once.
    static constexpr size_t kCapacity = 32;

    /// One buffer or segment held by another node.
    struct Hold {
        ObjectId area;         ///< The pool or heap.
        uint32_t address = 0;  ///< The buffer's or segment's start.
        uint16_t node = 0;     ///< The node whose task holds it.
    };

    /// Whether another hold fits.
    bool hasRoom() const { return count_ < kCapacity; }

    /// Notes that @p node holds @p address of @p area; false when the table is full. O(capacity).
    bool add(ObjectId area, uint32_t address, uint16_t node);

    /// Whether @p node may return @p address of @p area: Ok when it holds
    /// it, NotOwner when another node does, InvalidArgument when no node
    /// does (not handed out by this table: another node cannot have it). O(capacity).
    Status check(ObjectId area, uint32_t address, uint16_t node) const;

    /// Forgets the hold of @p address of @p area, once it is returned. O(capacity).
    void remove(ObjectId area, uint32_t address);

    /// Takes out up to @p room holds of @p node into @p out; how many.
    /// O(capacity). Called until it gives fewer than @p room.
    size_t takeHoldsOf(uint16_t node, Hold* out, size_t room);

    /// Holds in the table.
    size_t count() const { return count_; }

private:
    // The slot of @p address of @p area, or kCapacity.
    size_t find(ObjectId area, uint32_t address) const;

    Hold holds_[kCapacity];
    bool used_[kCapacity] = {};
    size_t count_ = 0;
};

} // namespace dcos::internal
