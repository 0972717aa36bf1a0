// The network interfaces manager's kernel side (seed 7.13): one static
// AddressMap, the super-user check on the services that change it and the
// interrupt guard around every walk of its tables.
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/internal/AddressMap.hpp>
#include <dcos/internal/ConfigurationService.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/NetworkTables.hpp>
#include <dcos/internal/RemoteAgent.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos {

namespace {

using Lock = arch_x86::InterruptGuard;

constinit internal::NetworkTables tables;

// A service that changes the tables: in task context, for a super-user
// caller, @p change(tables) under the guard; its status (or result) else.
template <typename Change>
auto changeTables(Change change) -> decltype(change(tables))
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    Lock lock;
    return change(tables);
}

} // namespace

DCOS_CONFIGURATION_SERVICE Result<uint8_t> NetworkInterfacesManager::AddInterface(
    InterfaceKind kind, uint8_t channel, NetworkAddress address, uint8_t prefixLength, uint32_t physical)
{
    return changeTables([&](internal::NetworkTables& t) {
        return t.addInterface(NetworkInterface{kind, channel, address, prefixLength, physical});
    });
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::RemoveInterface(uint8_t interface)
{
    if (!internal::inInterruptContext() && internal::currentTaskIsSuperUser()) {
        // No transaction may leave by an interface that is gone.
        internal::detachRemoteLink(interface);
    }
    return changeTables([&](internal::NetworkTables& t) { return t.removeInterface(interface); });
}

Result<NetworkInterface> NetworkInterfacesManager::GetInterface(uint8_t interface)
{
    Lock lock;
    return tables.interface(interface);
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::MapNode(uint16_t node, NetworkAddress address)
{
    return changeTables([&](internal::NetworkTables& t) { return t.mapNode(node, address); });
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::UnmapNode(uint16_t node, NetworkAddress address)
{
    return changeTables([&](internal::NetworkTables& t) { return t.unmapNode(node, address); });
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::SetPhysicalAddress(NetworkAddress address,
                                                                              uint32_t physical)
{
    return changeTables([&](internal::NetworkTables& t) { return t.setPhysicalAddress(address, physical); });
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::ClearPhysicalAddress(NetworkAddress address)
{
    return changeTables([&](internal::NetworkTables& t) { return t.clearPhysicalAddress(address); });
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::AddRoute(NetworkAddress destination,
                                                                    uint8_t prefixLength, NetworkAddress gateway)
{
    return changeTables([&](internal::NetworkTables& t) { return t.addRoute(destination, prefixLength, gateway); });
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::RemoveRoute(NetworkAddress destination,
                                                                       uint8_t prefixLength)
{
    return changeTables([&](internal::NetworkTables& t) { return t.removeRoute(destination, prefixLength); });
}

Result<NextHop> NetworkInterfacesManager::Resolve(uint16_t node)
{
    Lock lock;
    return tables.resolve(node, internal::localNode());
}

Result<uint16_t> NetworkInterfacesManager::NodeAt(uint8_t interface, uint32_t physical)
{
    Lock lock;
    return tables.nodeAt(interface, physical);
}

namespace internal {

void copyNetworkTables(NetworkTables& copy)
{
    Lock lock;
    copy = tables;
}

size_t gatewayHops(NextHop (&hops)[NetworkTables::kRoutes])
{
    Lock lock;
    return tables.gatewayHops(hops);
}

} // namespace internal

} // namespace dcos
