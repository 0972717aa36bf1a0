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

} // namespace dcos::internal
