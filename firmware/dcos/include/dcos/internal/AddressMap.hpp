// The network interfaces manager's tables and their resolution (seed 7.13),
// free of kernel and hardware: the local interfaces, the logical node to
// network address mapping, the neighbours' physical addresses and the
// routes. NetworkInterfacesManager.hpp describes what each means; the
// kernel side (src/network/NetworkInterfacesManager.cpp) adds the
// super-user check and the interrupt guard around one static instance.
//
// Every table is an array of fixed capacity with a use flag per entry, so
// the class needs no memory but its own and each operation walks at most
// one table's capacity. The class does no locking; its owner serialises
// calls.
#pragma once

#include <dcos/NetworkInterfacesManager.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// Capacities of the tables.
struct AddressMapCapacities {
    size_t interfaces;
    size_t nodeAddresses;
    size_t neighbours;
    size_t routes;
};

template <AddressMapCapacities kCapacities>
class AddressMap {
public:
    static_assert(kCapacities.interfaces > 0 && kCapacities.interfaces <= 255, "interface numbers are 8 bits");
    static_assert(kCapacities.nodeAddresses > 0 && kCapacities.neighbours > 0 && kCapacities.routes > 0);

    static constexpr size_t kInterfaces = kCapacities.interfaces;
    static constexpr size_t kNodeAddresses = kCapacities.nodeAddresses;
    static constexpr size_t kNeighbours = kCapacities.neighbours;
    static constexpr size_t kRoutes = kCapacities.routes;

    /// A node's network address, as MapNode made it.
    struct NodeAddress {
        uint16_t node;
        NetworkAddress address;
    };
    /// A neighbour's physical address, as SetPhysicalAddress made it.
    struct Neighbour {
        NetworkAddress address;
        uint32_t physical;
    };
    /// A route, as AddRoute made it.
    struct Route {
        NetworkAddress destination;
        uint8_t prefixLength;
        NetworkAddress gateway;
    };

    constexpr AddressMap() = default;

    Result<uint8_t> addInterface(const NetworkInterface& interface)
    {
        if (!interface.address.isUnicast() || !validPrefix(interface.prefixLength)
            || !isPhysicalAddressOf(interface.kind, interface.physical)) {
            return Status::InvalidArgument;
        }
        const Result<size_t> free = freeEntry(interfaceUsed_, [this, &interface](size_t i) {
            return interfaces_[i].address == interface.address
                   || (interfaces_[i].kind == interface.kind && interfaces_[i].channel == interface.channel);
        });
        if (!free.ok()) {
            return free.status();
        }
        interfaces_[free.value()] = interface;
        interfaceUsed_[free.value()] = true;
        return static_cast<uint8_t>(free.value());
    }

    Status removeInterface(uint8_t number)
    {
        if (number >= kInterfaces || !interfaceUsed_[number]) {
            return Status::NotFound;
        }
        interfaceUsed_[number] = false;
        interfaces_[number] = NetworkInterface{};
        return Status::Ok;
    }

    Result<NetworkInterface> interface(uint8_t number) const
    {
        if (number >= kInterfaces || !interfaceUsed_[number]) {
            return Status::NotFound;
        }
        return interfaces_[number];
    }

    Status mapNode(uint16_t node, NetworkAddress address)
    {
        if (!address.isUnicast()) {
            return Status::InvalidArgument;
        }
        const Result<size_t> free =
            freeEntry(nodeUsed_, [this, address](size_t i) { return nodes_[i].address == address; });
        if (!free.ok()) {
            return free.status();
        }
        // Entries are tried in the order they were mapped: a sequence number
        // keeps that order whichever free entry the mapping lands in.
        nodes_[free.value()] = NodeAddress{node, address};
        nodeOrder_[free.value()] = ++mappings_;
        nodeUsed_[free.value()] = true;
        return Status::Ok;
    }

    Status unmapNode(uint16_t node, NetworkAddress address)
    {
        return releaseEntry(nodeUsed_,
                            [this, node, address](size_t i) { return nodes_[i].node == node && nodes_[i].address == address; });
    }

    Status setPhysicalAddress(NetworkAddress address, uint32_t physical)
    {
        if (!address.isUnicast()) {
            return Status::InvalidArgument;
        }
        const size_t local = interfaceHolding(address);
        if (local == kInterfaces || !isPhysicalAddressOf(interfaces_[local].kind, physical)) {
            return Status::InvalidArgument;
        }
        size_t known = kNeighbours;
        const Result<size_t> free = freeEntry(neighbourUsed_, [this, address, &known](size_t i) {
            known = neighbours_[i].address == address ? i : known;
            return known == i;
        });
        if (known != kNeighbours) {
            neighbours_[known].physical = physical; // Replaced.
            return Status::Ok;
        }
        if (!free.ok()) {
            return free.status();
        }
        neighbours_[free.value()] = Neighbour{address, physical};
        neighbourUsed_[free.value()] = true;
        return Status::Ok;
    }

    Status clearPhysicalAddress(NetworkAddress address)
    {
        return releaseEntry(neighbourUsed_, [this, address](size_t i) { return neighbours_[i].address == address; });
    }

    Status addRoute(NetworkAddress destination, uint8_t prefixLength, NetworkAddress gateway)
    {
        if (!validPrefix(prefixLength) || (destination.raw() & ~NetworkAddress::maskOf(prefixLength)) != 0
            || !gateway.isUnicast()) {
            return Status::InvalidArgument;
        }
        const Result<size_t> free = freeEntry(routeUsed_, [this, destination, prefixLength](size_t i) {
            return routes_[i].destination == destination && routes_[i].prefixLength == prefixLength;
        });
        if (!free.ok()) {
            return free.status();
        }
        routes_[free.value()] = Route{destination, prefixLength, gateway};
        routeUsed_[free.value()] = true;
        return Status::Ok;
    }

    Status removeRoute(NetworkAddress destination, uint8_t prefixLength)
    {
        return releaseEntry(routeUsed_, [this, destination, prefixLength](size_t i) {
            return routes_[i].destination == destination && routes_[i].prefixLength == prefixLength;
        });
    }

    /// NetworkInterfacesManager::Resolve for a map whose own node is @p localNode.
    Result<NextHop> resolve(uint16_t node, uint16_t localNode) const
    {
        if (node == localNode) {
            return Status::InvalidArgument;
        }
        bool mapped = false;
        // The node's addresses in the order they were mapped: each round
        // takes the oldest mapping not tried yet.
        uint32_t after = 0;
        for (;;) {
            size_t next = kNodeAddresses;
            for (size_t i = 0; i < kNodeAddresses; ++i) {
                if (nodeUsed_[i] && nodes_[i].node == node && nodeOrder_[i] > after
                    && (next == kNodeAddresses || nodeOrder_[i] < nodeOrder_[next])) {
                    next = i;
                }
            }
            if (next == kNodeAddresses) {
                return mapped ? Status::Unreachable : Status::NotFound;
            }
            mapped = true;
            after = nodeOrder_[next];
            NextHop hop;
            if (hopTo(nodes_[next].address, hop)) {
                return hop;
            }
        }
    }

    /// NetworkInterfacesManager::NodeAt: the logical node whose network
    /// address, in interface @p interface's subnet, has physical address
    /// @p physical. NotFound when no neighbour there has it or no node is
    /// mapped onto its address. O(neighbours + node addresses).
    Result<uint16_t> nodeAt(uint8_t interface, uint32_t physical) const
    {
        if (interface >= kInterfaces || !interfaceUsed_[interface]) {
            return Status::NotFound;
        }
        const NetworkInterface& local = interfaces_[interface];
        for (size_t n = 0; n < kNeighbours; ++n) {
            if (!neighbourUsed_[n] || neighbours_[n].physical != physical ||
                !neighbours_[n].address.isIn(local.address, local.prefixLength)) {
                continue;
            }
            for (size_t i = 0; i < kNodeAddresses; ++i) {
                if (nodeUsed_[i] && nodes_[i].address == neighbours_[n].address) {
                    return nodes_[i].node;
                }
            }
        }
        return Status::NotFound;
    }

    /// Visits every entry of each table, for listings: @p visit(entry) with
    /// the interface's number first for interfaces.
    template <typename Visit>
    void forEachInterface(Visit visit) const
    {
        for (size_t i = 0; i < kInterfaces; ++i) {
            if (interfaceUsed_[i]) {
                visit(static_cast<uint8_t>(i), interfaces_[i]);
            }
        }
    }
    template <typename Visit>
    void forEachNodeAddress(Visit visit) const
    {
        for (size_t i = 0; i < kNodeAddresses; ++i) {
            if (nodeUsed_[i]) {
                visit(nodes_[i]);
            }
        }
    }
    template <typename Visit>
    void forEachNeighbour(Visit visit) const
    {
        for (size_t i = 0; i < kNeighbours; ++i) {
            if (neighbourUsed_[i]) {
                visit(neighbours_[i]);
            }
        }
    }
    template <typename Visit>
    void forEachRoute(Visit visit) const
    {
        for (size_t i = 0; i < kRoutes; ++i) {
            if (routeUsed_[i]) {
                visit(routes_[i]);
            }
        }
    }

    /// The first hops to the routes' gateways, each once: a gateway on a
    /// local subnet with a physical address, into @p hops; how many.
    /// O(routes × (routes + interfaces + neighbours)).
    size_t gatewayHops(NextHop (&hops)[kRoutes]) const
    {
        size_t count = 0;
        for (size_t i = 0; i < kRoutes; ++i) {
            NextHop hop;
            if (!routeUsed_[i] || interfaceHolding(routes_[i].gateway) == kInterfaces ||
                !hopTo(routes_[i].gateway, hop)) {
                continue;
            }
            bool seen = false;
            for (size_t j = 0; j < count; ++j) {
                seen = seen || (hops[j].interface == hop.interface && hops[j].physical == hop.physical);
            }
            if (!seen) {
                hops[count++] = hop;
            }
        }
        return count;
    }

private:
    // The first free entry of a table whose use flags are @p used, after a
    // walk of the entries in use that stops at the first one @p clashes
    // with: AlreadyExists then, TableFull when no entry is free.
    template <size_t kEntries, typename Clashes>
    static Result<size_t> freeEntry(const bool (&used)[kEntries], Clashes clashes)
    {
        size_t free = kEntries;
        for (size_t i = 0; i < kEntries; ++i) {
            if (!used[i]) {
                free = free == kEntries ? i : free;
            } else if (clashes(i)) {
                return Status::AlreadyExists;
            }
        }
        if (free == kEntries) {
            return Status::TableFull;
        }
        return free;
    }

    // Frees the entry in use that @p matches; NotFound when none does.
    template <size_t kEntries, typename Matches>
    static Status releaseEntry(bool (&used)[kEntries], Matches matches)
    {
        for (size_t i = 0; i < kEntries; ++i) {
            if (used[i] && matches(i)) {
                used[i] = false;
                return Status::Ok;
            }
        }
        return Status::NotFound;
    }

    static constexpr bool validPrefix(uint8_t prefixLength)
    {
        return prefixLength >= NetworkAddress::kMinimumPrefixLength
               && prefixLength <= NetworkAddress::kMaximumPrefixLength;
    }

    // The lowest-numbered local interface whose subnet holds @p address, or kInterfaces.
    size_t interfaceHolding(NetworkAddress address) const
    {
        for (size_t i = 0; i < kInterfaces; ++i) {
            if (interfaceUsed_[i] && address.isIn(interfaces_[i].address, interfaces_[i].prefixLength)) {
                return i;
            }
        }
        return kInterfaces;
    }

    // The physical address of neighbour @p address; false when none is set.
    bool physicalOf(NetworkAddress address, uint32_t& physical) const
    {
        for (size_t i = 0; i < kNeighbours; ++i) {
            if (neighbourUsed_[i] && neighbours_[i].address == address) {
                physical = neighbours_[i].physical;
                return true;
            }
        }
        return false;
    }

    // The first hop towards @p destination: directly on a local subnet, or
    // through the gateway of the longest route holding it, which must be on
    // a local subnet itself (a gateway is one hop away; further hops are
    // the gateway's to make).
    bool hopTo(NetworkAddress destination, NextHop& hop) const
    {
        NetworkAddress via = destination;
        size_t local = interfaceHolding(destination);
        if (local == kInterfaces) {
            size_t best = kRoutes;
            for (size_t i = 0; i < kRoutes; ++i) {
                if (routeUsed_[i] && destination.isIn(routes_[i].destination, routes_[i].prefixLength)
                    && (best == kRoutes || routes_[i].prefixLength > routes_[best].prefixLength)) {
                    best = i;
                }
            }
            if (best == kRoutes) {
                return false;
            }
            via = routes_[best].gateway;
            local = interfaceHolding(via);
            if (local == kInterfaces) {
                return false;
            }
        }
        uint32_t physical = 0;
        if (!physicalOf(via, physical) || !isPhysicalAddressOf(interfaces_[local].kind, physical)) {
            return false;
        }
        hop.interface = static_cast<uint8_t>(local);
        hop.physical = physical;
        hop.destination = destination;
        hop.via = via;
        return true;
    }

    NetworkInterface interfaces_[kInterfaces] = {};
    bool interfaceUsed_[kInterfaces] = {};
    NodeAddress nodes_[kNodeAddresses] = {};
    uint32_t nodeOrder_[kNodeAddresses] = {};
    bool nodeUsed_[kNodeAddresses] = {};
    uint32_t mappings_ = 0;
    Neighbour neighbours_[kNeighbours] = {};
    bool neighbourUsed_[kNeighbours] = {};
    Route routes_[kRoutes] = {};
    bool routeUsed_[kRoutes] = {};
};

} // namespace dcos::internal
