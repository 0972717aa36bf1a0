// The network interfaces manager's kernel side (seed 7.13): one static
// AddressMap, the super-user check on the services that change it and the
// interrupt guard around every walk of its tables.
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/internal/AddressMap.hpp>
#include <dcos/internal/ConfigurationService.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/NetworkTables.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos {

namespace {

using Lock = arch_x86::InterruptGuard;

constinit internal::NetworkTables tables;

// What the services that change the tables check first: task context and
// a super-user caller.
Status checkChange()
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    return internal::currentTaskIsSuperUser() ? Status::Ok : Status::NotPermitted;
}

} // namespace

DCOS_CONFIGURATION_SERVICE Result<uint8_t> NetworkInterfacesManager::AddInterface(
    InterfaceKind kind, uint8_t channel, NetworkAddress address, uint8_t prefixLength, uint32_t physical)
{
    if (const Status status = checkChange(); status != Status::Ok) {
        return status;
    }
    Lock lock;
    return tables.addInterface(NetworkInterface{kind, channel, address, prefixLength, physical});
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::RemoveInterface(uint8_t interface)
{
    if (const Status status = checkChange(); status != Status::Ok) {
        return status;
    }
    Lock lock;
    return tables.removeInterface(interface);
}

Result<NetworkInterface> NetworkInterfacesManager::GetInterface(uint8_t interface)
{
    Lock lock;
    return tables.interface(interface);
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::MapNode(uint16_t node, NetworkAddress address)
{
    if (const Status status = checkChange(); status != Status::Ok) {
        return status;
    }
    Lock lock;
    return tables.mapNode(node, address);
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::UnmapNode(uint16_t node, NetworkAddress address)
{
    if (const Status status = checkChange(); status != Status::Ok) {
        return status;
    }
    Lock lock;
    return tables.unmapNode(node, address);
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::SetPhysicalAddress(NetworkAddress address,
                                                                              uint32_t physical)
{
    if (const Status status = checkChange(); status != Status::Ok) {
        return status;
    }
    Lock lock;
    return tables.setPhysicalAddress(address, physical);
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::ClearPhysicalAddress(NetworkAddress address)
{
    if (const Status status = checkChange(); status != Status::Ok) {
        return status;
    }
    Lock lock;
    return tables.clearPhysicalAddress(address);
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::AddRoute(NetworkAddress destination,
                                                                    uint8_t prefixLength, NetworkAddress gateway)
{
    if (const Status status = checkChange(); status != Status::Ok) {
        return status;
    }
    Lock lock;
    return tables.addRoute(destination, prefixLength, gateway);
}

DCOS_CONFIGURATION_SERVICE Status NetworkInterfacesManager::RemoveRoute(NetworkAddress destination,
                                                                       uint8_t prefixLength)
{
    if (const Status status = checkChange(); status != Status::Ok) {
        return status;
    }
    Lock lock;
    return tables.removeRoute(destination, prefixLength);
}

Result<NextHop> NetworkInterfacesManager::Resolve(uint16_t node)
{
    Lock lock;
    return tables.resolve(node, internal::localNode());
}

namespace internal {

void copyNetworkTables(NetworkTables& copy)
{
    Lock lock;
    copy = tables;
}

} // namespace internal

} // namespace dcos
