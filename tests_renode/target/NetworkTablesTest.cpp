// The network interfaces manager's services on the target (seed 7.13): the
// super user builds the tables of the sender of the seed's Fig. 7.15 (the
// board, node 1, on net 130.2) and resolves node 3 on net 130.1 behind
// gateway node 2; a task without the privilege may resolve but not change
// them.
#include "KernelTestSupport.hpp"

#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/KernelContext.hpp>

namespace target_test {

namespace {

using dcos::InterfaceKind;
using dcos::NetworkAddress;
using dcos::NetworkInterfacesManager;
using dcos::NextHop;
using dcos::Status;

constexpr NetworkAddress kOwn = NetworkAddress::fromOctets(130, 2, 0, 3);
constexpr NetworkAddress kGateway = NetworkAddress::fromOctets(130, 2, 0, 2);
constexpr NetworkAddress kFar = NetworkAddress::fromOctets(130, 1, 0, 3);
constexpr NetworkAddress kFarNet = NetworkAddress::fromOctets(130, 1, 0, 0);

Status unprivilegedChange = Status::Ok;
Status unprivilegedResolve = Status::Ok;

void unprivileged(uintptr_t)
{
    unprivilegedChange = NetworkInterfacesManager::MapNode(7, NetworkAddress::fromOctets(130, 2, 0, 7));
    unprivilegedResolve = NetworkInterfacesManager::Resolve(3).status();
    finished();
}

bool networkTables(shell::Shell& shell)
{
    const dcos::Result<uint8_t> interface = NetworkInterfacesManager::AddInterface(InterfaceKind::Can, 0, kOwn, 16, 3);
    bool ok = check(shell, interface.ok() && interface.value() == 0, "the CAN interface is number 0");
    ok = checkStatus(shell, NetworkInterfacesManager::MapNode(3, kFar), Status::Ok, "map node 3") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::MapNode(2, kGateway), Status::Ok, "map node 2") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::Resolve(3).status(), Status::Unreachable,
                     "node 3 before its route") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::AddRoute(kFarNet, 16, kGateway), Status::Ok, "the route") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::SetPhysicalAddress(kGateway, 2), Status::Ok,
                     "the gateway's CAN node") && ok;
    const dcos::Result<NextHop> hop = NetworkInterfacesManager::Resolve(3);
    ok = check(shell, hop.ok() && hop.value().interface == 0 && hop.value().physical == 2 && hop.value().via == kGateway
                          && hop.value().destination == kFar,
               "node 3 goes to CAN node 2, the gateway") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::Resolve(dcos::internal::localNode()).status(),
                     Status::InvalidArgument, "the local node is not resolved") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::MapNode(9, NetworkAddress::fromOctets(224, 0, 0, 9)),
                     Status::InvalidArgument, "a multicast address is no node's") && ok;

    // A task without the privilege.
    dcos::TaskAttributes attributes;
    attributes.name = "plain";
    attributes.priority = 10;
    attributes.stackSize = 4096;
    ok = check(shell, dcos::taskAgent.Create(attributes, unprivileged, 0).ok(), "a plain task") && ok;
    ok = waitForDone(shell, 1) && ok;
    ok = checkStatus(shell, unprivilegedChange, Status::NotPermitted, "it may not change the tables") && ok;
    ok = checkStatus(shell, unprivilegedResolve, Status::Ok, "it may resolve") && ok;

    // Left as they were found, for the other tests of the same boot.
    ok = checkStatus(shell, NetworkInterfacesManager::RemoveRoute(kFarNet, 16), Status::Ok, "remove the route") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::ClearPhysicalAddress(kGateway), Status::Ok, "forget node 2")
         && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::UnmapNode(3, kFar), Status::Ok, "unmap node 3") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::UnmapNode(2, kGateway), Status::Ok, "unmap node 2") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::RemoveInterface(0), Status::Ok, "remove the interface") && ok;
    ok = checkStatus(shell, NetworkInterfacesManager::Resolve(3).status(), Status::NotFound, "empty again") && ok;
    return ok;
}

DCOS_TARGET_TEST(networkTablesTest, "nettables", "the network interfaces manager's tables and their privilege",
                 networkTables);

} // namespace

} // namespace target_test
