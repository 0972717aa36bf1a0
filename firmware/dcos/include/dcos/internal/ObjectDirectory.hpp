// Every object table of the node, by object type, for the configuration
// services that list objects whatever their agent: the system engineering
// interface agent's ListObjects and NodeStatistics (seed 7.14,
// docs/protocols/config.md). Each agent hands out a view of its table
// (ObjectTableView: where the slot headers are, how many are active and
// used); the directory reads ids, owners and names from the headers with
// interrupts disabled per slot, so a listing is O(N) in the table's active
// slots and never holds interrupts off for more than one slot's copy.
// Configuration services only: nothing on a real-time path calls these.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/internal/ObjectTableCore.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// One object as a listing shows it.
struct ObjectSummary {
    ObjectId id;
    ObjectId owner; ///< Null for the system.
    Visibility visibility = Visibility::Local;
    char name[kObjectNameCapacity] = {};
};

/// The view of @p type's table; InvalidArgument for a type the node keeps
/// no table of (Process, DsmSubscription, NetworkInterface, Module and the
/// reserved ones).
Result<ObjectTableView> objectTableOf(ObjectType type);

/// The object in slot @p slot of @p view, copied with interrupts disabled;
/// false when the slot is free or not active.
bool objectAt(const ObjectTableView& view, size_t slot, ObjectSummary& out);

/// The slot of @p id in @p view (O(N)); false when no active slot holds it.
bool slotOfObject(const ObjectTableView& view, ObjectId id, size_t& slot);

// Each agent's table, defined beside the table in the agent's source.
ObjectTableView taskTableView();
ObjectTableView timerTableView();
ObjectTableView deviceTableView();
ObjectTableView bufferPoolTableView();
ObjectTableView heapTableView();
ObjectTableView messagePortTableView();
ObjectTableView publisherTableView();
ObjectTableView semaphoreTableView();

} // namespace dcos::internal
