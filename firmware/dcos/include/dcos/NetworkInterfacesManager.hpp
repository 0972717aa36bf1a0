// The network interfaces manager's tables (seed 7.13): how a logical node
// is reached over the fieldbuses.
//
// Every object id carries its node in its top 16 bits, the logical address.
// The manager maps a logical node onto one or more network addresses
// (NetworkAddress.hpp; several when the node is multi-homed, in the order
// they were mapped, which is the order they are tried), and a network
// address onto the physical address of the interface that carries it (the
// CAN node number, the Modbus slave address, the processor of the
// dual-Pentium board's shared-memory link). The local node's own interfaces
// each have a network address and a subnet; a destination in the subnet of
// one of them is reached directly, any other through the gateway of the
// route whose destination subnet holds it (the longest such), which must be
// reached directly. So a request from node 3 to node 1 of Fig. 7.15 goes to
// gateway node 2, whose own manager sends it on over its second network.
//
// The tables are kernel memory of fixed size (KernelConfig.hpp) and are set
// at run time by a super-user task with the services below; reading them
// (Resolve, the console command "net") is open to every task. The later
// remote primitives resolve every request's node here. Every service takes
// interrupts off for its walk of one table: O(entries of that table),
// bounded by its capacity and independent of the object tables.
//
//     using dcos::NetworkAddress;
//     NetworkInterfacesManager::AddInterface(InterfaceKind::Can, 0, NetworkAddress::fromOctets(130, 1, 0, 3), 16, 3);
//     NetworkInterfacesManager::MapNode(1, NetworkAddress::fromOctets(130, 2, 0, 1));
//     NetworkInterfacesManager::AddRoute(NetworkAddress::fromOctets(130, 2, 0, 0), 16, NetworkAddress::fromOctets(130, 1, 0, 2));
//     NetworkInterfacesManager::SetPhysicalAddress(NetworkAddress::fromOctets(130, 1, 0, 2), 2);
//     NetworkInterfacesManager::Resolve(1);  // interface 0, CAN node 2, via 130.1.0.2
#pragma once

#include <dcos/NetworkAddress.hpp>
#include <dcos/NetworkLink.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace dcos {

/// The kind of network an interface attaches to.
enum class InterfaceKind : uint8_t {
    Can = 0,          ///< A CAN controller (SJA1000); physical address: the CAN node number, 0 to 127.
    ModbusRtu = 1,    ///< A Modbus RTU line (16550); physical address: the slave address, 1 to 247.
    SharedMemory = 2, ///< The dual-Pentium board's link between its two nodes; physical address: the processor, 0 or 1.
};

/// A short name of an interface kind, for the console and logs.
constexpr const char* interfaceKindName(InterfaceKind kind)
{
    switch (kind) {
    case InterfaceKind::Can: return "can";
    case InterfaceKind::ModbusRtu: return "modbus";
    case InterfaceKind::SharedMemory: return "shm";
    }
    return "?";
}

/// Whether @p physical is a physical address an interface of kind @p kind can have.
constexpr bool isPhysicalAddressOf(InterfaceKind kind, uint32_t physical)
{
    switch (kind) {
    case InterfaceKind::Can: return physical <= 127;
    case InterfaceKind::ModbusRtu: return physical >= 1 && physical <= 247;
    case InterfaceKind::SharedMemory: return physical <= 1;
    }
    return false;
}

/// One of the local node's interfaces.
struct NetworkInterface {
    InterfaceKind kind = InterfaceKind::Can;
    /// Which controller of that kind on the board (the first CAN controller is 0).
    uint8_t channel = 0;
    /// The interface's own network address and its subnet's prefix length.
    NetworkAddress address;
    uint8_t prefixLength = 0;
    /// The interface's own physical address on its network.
    uint32_t physical = 0;
};

/// Where a request to a node goes first.
struct NextHop {
    /// The local interface it leaves by (the number AddInterface gave).
    uint8_t interface = 0;
    /// The physical address it is sent to on that interface's network.
    uint32_t physical = 0;
    /// The node's network address that was chosen.
    NetworkAddress destination;
    /// The address the frame goes to: the destination itself, or the gateway.
    NetworkAddress via;
};

/// The network interfaces manager's services (seed 7.13). The class has
/// no state; its tables live in the kernel. Setting them needs a super-user
/// task (NotPermitted otherwise) and task context (InInterrupt otherwise).
class NetworkInterfacesManager {
public:
    /// Adds a local interface; returns its number, the lowest free one.
    /// InvalidArgument for an address that is not unicast, a prefix length
    /// outside 8 to 32, or a physical address the kind cannot have;
    /// AlreadyExists when an interface has that address or that kind and
    /// channel; TableFull.
    static Result<uint8_t> AddInterface(InterfaceKind kind, uint8_t channel, NetworkAddress address,
                                        uint8_t prefixLength, uint32_t physical);
    /// Removes a local interface, detaching its link first. NotFound when
    /// there is none with that number.
    static Status RemoveInterface(uint8_t interface);

    /// Gives interface @p interface the driver that carries it, and starts
    /// the remote agent (RemoteAgent.hpp) on first use: from then on remote
    /// transactions to nodes reached over the interface go through @p link,
    /// and requests arriving on it are served. @p link must outlive the
    /// attachment. NotFound when there is no such interface; AlreadyExists
    /// when it has a link; the link's Start status; NoMemory or TableFull
    /// when the remote agent's tasks cannot be created.
    static Status AttachLink(uint8_t interface, NetworkLink& link);
    /// Stops and forgets the link of @p interface; transactions waiting on
    /// it end by their watchdog. NotFound when it has none.
    static Status DetachLink(uint8_t interface);
    /// The interface with that number; NotFound when there is none.
    static Result<NetworkInterface> GetInterface(uint8_t interface);

    /// Maps logical node @p node onto network address @p address, after the
    /// addresses it has already (they are tried in that order).
    /// InvalidArgument for an address that is not unicast; AlreadyExists
    /// when the address is mapped already (to this node or another); TableFull.
    static Status MapNode(uint16_t node, NetworkAddress address);
    /// Undoes MapNode; NotFound when that mapping does not exist.
    static Status UnmapNode(uint16_t node, NetworkAddress address);

    /// Sets the physical address of the neighbour with network address
    /// @p address (a node or gateway on one of the local interfaces'
    /// networks), replacing the one it had. InvalidArgument for an address
    /// that is not unicast or in no local interface's subnet, or a physical
    /// address that interface's kind cannot have; TableFull.
    static Status SetPhysicalAddress(NetworkAddress address, uint32_t physical);
    /// Forgets a neighbour's physical address; NotFound when none is set.
    static Status ClearPhysicalAddress(NetworkAddress address);

    /// Routes the subnet @p destination / @p prefixLength through @p gateway.
    /// InvalidArgument for a prefix length outside 8 to 32, a destination
    /// with bits set beyond its prefix, or a gateway that is not unicast;
    /// AlreadyExists for a route to that subnet; TableFull.
    static Status AddRoute(NetworkAddress destination, uint8_t prefixLength, NetworkAddress gateway);
    /// Removes the route to that subnet; NotFound when there is none.
    static Status RemoveRoute(NetworkAddress destination, uint8_t prefixLength);

    /// Where a request to logical node @p node goes first: each of the
    /// node's network addresses in turn, directly when a local interface's
    /// subnet holds it, else through the gateway of the longest route that
    /// holds it; the first that leads to a known physical address wins.
    /// InvalidArgument for the local node; NotFound when the node is
    /// mapped to no address; Unreachable when none of its addresses leads
    /// anywhere. Open to every task and to interrupt handlers.
    static Result<NextHop> Resolve(uint16_t node);
    /// The reverse mapping (seed 7.13): the logical node that sent from
    /// physical address @p physical on interface @p interface, the node
    /// mapped onto the neighbour's network address there. A multi-homed
    /// node is found on each of its interfaces. NotFound when the tables
    /// do not know the sender. Open to every task and to interrupt handlers.
    static Result<uint16_t> NodeAt(uint8_t interface, uint32_t physical);
};

} // namespace dcos
