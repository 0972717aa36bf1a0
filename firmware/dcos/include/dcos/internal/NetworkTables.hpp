// The network interfaces manager's tables as the kernel sizes them
// (KernelConfig.hpp), for its kernel side and its console command.
#pragma once

#include <dcos/internal/AddressMap.hpp>
#include <dcos/internal/KernelConfig.hpp>

namespace dcos::internal {

using NetworkTables = AddressMap<AddressMapCapacities{kNetworkInterfaces, kNetworkNodeAddresses, kNetworkNeighbours,
                                                      kNetworkRoutes}>;

/// Copies the tables under the manager's guard, so that a listing prints
/// them with interrupts enabled. O(size of the tables).
void copyNetworkTables(NetworkTables& copy);

/// The first hops to the routes' gateways, each once (AddressMap::gatewayHops),
/// under the manager's guard: where a name query goes beyond the buses this
/// node is attached to (docs/protocols/remote-transactions.md, "Gateways").
size_t gatewayHops(NextHop (&hops)[NetworkTables::kRoutes]);

} // namespace dcos::internal
