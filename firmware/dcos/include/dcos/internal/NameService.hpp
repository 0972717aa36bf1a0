// This node's part of distributed names (seed 6.4, NameToObject): the
// object of a type and name that a lookup from a given scope may see, in
// whichever agent's table holds that type. The remote agent calls it for
// the name queries of other nodes (docs/protocols/remote-transactions.md,
// "Names"), asking with Global, or Regional within the controller.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

namespace dcos::internal {

/// This node's object of @p type named @p name and visible from
/// @p askingScope. NotFound also for a type whose objects have no names.
/// Cost O(1) expected (the tables hash their names).
Result<ObjectId> localNameToObject(ObjectType type, const char* name, Visibility askingScope);

} // namespace dcos::internal
