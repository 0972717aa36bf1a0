// Host tests of the network interfaces manager's addresses and tables (seed
// 7.13): the address kinds and text form, every table's rules and errors,
// resolution directly, through a gateway (the seed's Fig. 7.15), for a
// multi-homed node, by the longest route, and against an independent model
// under random tables.
#include <dcos/NetworkAddress.hpp>
#include <dcos/internal/AddressMap.hpp>

#include <gtest/gtest.h>

#include <optional>
#include <random>
#include <string>
#include <vector>

namespace {

using dcos::InterfaceKind;
using dcos::NetworkAddress;
using dcos::NetworkInterface;
using dcos::NextHop;
using dcos::Status;
using Kind = NetworkAddress::Kind;

using Map = dcos::internal::AddressMap<dcos::internal::AddressMapCapacities{4, 8, 8, 4}>;

constexpr NetworkAddress address(uint8_t a, uint8_t b, uint8_t c, uint8_t d)
{
    return NetworkAddress::fromOctets(a, b, c, d);
}

NetworkInterface interfaceOf(InterfaceKind kind, uint8_t channel, NetworkAddress own, uint8_t prefixLength,
                             uint32_t physical)
{
    return NetworkInterface{kind, channel, own, prefixLength, physical};
}

std::string text(NetworkAddress value)
{
    char out[NetworkAddress::kTextSize];
    value.format(out);
    return out;
}

} // namespace

TEST(NetworkAddressTest, TheFirstOctetSaysTheKind)
{
    EXPECT_EQ(address(128, 0, 0, 1).kind(), Kind::Unicast);
    EXPECT_EQ(address(223, 255, 255, 254).kind(), Kind::Unicast);
    EXPECT_EQ(address(224, 0, 0, 1).kind(), Kind::Multicast);
    EXPECT_EQ(address(239, 255, 255, 255).kind(), Kind::Multicast);
    EXPECT_EQ(address(255, 255, 255, 255).kind(), Kind::LimitedBroadcast);
    EXPECT_EQ(address(130, 255, 255, 255).kind(), Kind::DirectedBroadcast);
    EXPECT_EQ(address(127, 0, 0, 1).kind(), Kind::Invalid);
    EXPECT_EQ(address(10, 1, 2, 3).kind(), Kind::Invalid);
    EXPECT_EQ(address(240, 0, 0, 1).kind(), Kind::Invalid);
    EXPECT_EQ(address(254, 255, 255, 255).kind(), Kind::Invalid);
}

TEST(NetworkAddressTest, SubnetsByPrefixLength)
{
    EXPECT_TRUE(address(130, 1, 7, 9).isIn(address(130, 1, 0, 0), 16));
    EXPECT_FALSE(address(130, 2, 7, 9).isIn(address(130, 1, 0, 0), 16));
    EXPECT_TRUE(address(130, 2, 7, 9).isIn(address(130, 1, 0, 0), 8));
    EXPECT_TRUE(address(130, 1, 0, 5).isIn(address(130, 1, 0, 5), 32));
    EXPECT_FALSE(address(130, 1, 0, 4).isIn(address(130, 1, 0, 5), 32));
    EXPECT_EQ(NetworkAddress::maskOf(8), 0xFF000000u);
    EXPECT_EQ(NetworkAddress::maskOf(20), 0xFFFFF000u);
    EXPECT_EQ(NetworkAddress::maskOf(32), 0xFFFFFFFFu);
}

TEST(NetworkAddressTest, TextRoundTrips)
{
    for (NetworkAddress value : {address(0, 0, 0, 0), address(130, 1, 0, 3), address(255, 255, 255, 255),
                                 address(9, 10, 99, 100)}) {
        NetworkAddress back;
        ASSERT_TRUE(NetworkAddress::parse(text(value).c_str(), back)) << text(value);
        EXPECT_EQ(back, value);
    }
    EXPECT_EQ(text(address(130, 1, 0, 3)), "130.1.0.3");
}

TEST(NetworkAddressTest, MalformedTextIsRefused)
{
    NetworkAddress out = address(130, 0, 0, 1);
    for (const char* bad : {"", "130.1.0", "130.1.0.3.4", "130.1.0.256", "130.1..3", "130.1.0.3 ", " 130.1.0.3",
                            "130.01.0.3", "a.b.c.d", "1300.1.0.3", "130.1.0.-3", "130.1.0.3/16"}) {
        EXPECT_FALSE(NetworkAddress::parse(bad, out)) << bad;
    }
    EXPECT_FALSE(NetworkAddress::parse(nullptr, out));
    EXPECT_EQ(out, address(130, 0, 0, 1)) << "untouched on failure";
}

TEST(AddressMapTest, InterfacesAreCheckedAndNumbered)
{
    Map map;
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 0, address(130, 1, 0, 3), 16, 3)).value(), 0);
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::ModbusRtu, 0, address(131, 1, 0, 3), 16, 3)).value(), 1);
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 0, address(132, 1, 0, 3), 16, 4)).status(),
              Status::AlreadyExists) << "the same controller twice";
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 1, address(130, 1, 0, 3), 16, 4)).status(),
              Status::AlreadyExists) << "the same address twice";
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 1, address(224, 1, 0, 3), 16, 4)).status(),
              Status::InvalidArgument) << "a multicast address";
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 1, address(133, 1, 0, 3), 7, 4)).status(),
              Status::InvalidArgument) << "a prefix shorter than the net id";
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 1, address(133, 1, 0, 3), 33, 4)).status(),
              Status::InvalidArgument);
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 1, address(133, 1, 0, 3), 16, 128)).status(),
              Status::InvalidArgument) << "CAN node numbers end at 127";
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::ModbusRtu, 1, address(133, 1, 0, 3), 16, 0)).status(),
              Status::InvalidArgument) << "Modbus slave 0 is the broadcast";
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::SharedMemory, 0, address(133, 1, 0, 3), 16, 2)).status(),
              Status::InvalidArgument) << "two processors";
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::SharedMemory, 0, address(133, 1, 0, 3), 16, 1)).value(), 2);
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 1, address(134, 1, 0, 3), 16, 1)).value(), 3);
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 2, address(135, 1, 0, 3), 16, 1)).status(),
              Status::TableFull);
    EXPECT_EQ(map.removeInterface(1), Status::Ok);
    EXPECT_EQ(map.removeInterface(1), Status::NotFound);
    EXPECT_EQ(map.removeInterface(200), Status::NotFound);
    EXPECT_EQ(map.interface(1).status(), Status::NotFound);
    EXPECT_EQ(map.addInterface(interfaceOf(InterfaceKind::Can, 2, address(135, 1, 0, 3), 16, 1)).value(), 1)
        << "the lowest free number";
    EXPECT_EQ(map.interface(1).value().address, address(135, 1, 0, 3));
}

TEST(AddressMapTest, TheSeedsFigureSevenFifteen)
{
    // Net 1 joins nodes 1 and 2, net 2 nodes 2 and 3; node 2 is the gateway.
    // Seen from node 3, on net 2 only.
    Map node3;
    ASSERT_TRUE(node3.addInterface(interfaceOf(InterfaceKind::Can, 0, address(130, 2, 0, 3), 16, 3)).ok());
    ASSERT_EQ(node3.mapNode(1, address(130, 1, 0, 1)), Status::Ok);
    ASSERT_EQ(node3.mapNode(2, address(130, 2, 0, 2)), Status::Ok);
    EXPECT_EQ(node3.resolve(1, 3).status(), Status::Unreachable) << "no route yet";
    ASSERT_EQ(node3.addRoute(address(130, 1, 0, 0), 16, address(130, 2, 0, 2)), Status::Ok);
    EXPECT_EQ(node3.resolve(1, 3).status(), Status::Unreachable) << "the gateway's physical address is unknown";
    ASSERT_EQ(node3.setPhysicalAddress(address(130, 2, 0, 2), 2), Status::Ok);
    const NextHop hop = node3.resolve(1, 3).value();
    EXPECT_EQ(hop.interface, 0);
    EXPECT_EQ(hop.physical, 2u);
    EXPECT_EQ(hop.destination, address(130, 1, 0, 1));
    EXPECT_EQ(hop.via, address(130, 2, 0, 2));
    const NextHop direct = node3.resolve(2, 3).value();
    EXPECT_EQ(direct.via, address(130, 2, 0, 2));
    EXPECT_EQ(direct.destination, address(130, 2, 0, 2));

    // Node 2, on both nets, sends it on over net 1 directly.
    Map node2;
    ASSERT_TRUE(node2.addInterface(interfaceOf(InterfaceKind::Can, 0, address(130, 1, 0, 2), 16, 2)).ok());
    ASSERT_TRUE(node2.addInterface(interfaceOf(InterfaceKind::ModbusRtu, 0, address(130, 2, 0, 2), 16, 2)).ok());
    ASSERT_EQ(node2.mapNode(1, address(130, 1, 0, 1)), Status::Ok);
    ASSERT_EQ(node2.setPhysicalAddress(address(130, 1, 0, 1), 1), Status::Ok);
    const NextHop onward = node2.resolve(1, 2).value();
    EXPECT_EQ(onward.interface, 0);
    EXPECT_EQ(onward.physical, 1u);
    EXPECT_EQ(onward.via, address(130, 1, 0, 1));
}

TEST(AddressMapTest, AMultiHomedNodeIsReachedByItsFirstWorkingAddress)
{
    Map map;
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::Can, 0, address(130, 1, 0, 9), 16, 9)).ok());
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::ModbusRtu, 0, address(131, 1, 0, 9), 16, 9)).ok());
    ASSERT_EQ(map.mapNode(5, address(130, 1, 0, 5)), Status::Ok);
    ASSERT_EQ(map.mapNode(5, address(131, 1, 0, 5)), Status::Ok);
    ASSERT_EQ(map.setPhysicalAddress(address(131, 1, 0, 5), 5), Status::Ok);
    EXPECT_EQ(map.resolve(5, 9).value().interface, 1) << "the CAN address has no physical address: the Modbus one";
    ASSERT_EQ(map.setPhysicalAddress(address(130, 1, 0, 5), 5), Status::Ok);
    EXPECT_EQ(map.resolve(5, 9).value().interface, 0) << "mapped first, tried first";
    ASSERT_EQ(map.removeInterface(0), Status::Ok); // The CAN bus is gone.
    EXPECT_EQ(map.resolve(5, 9).value().interface, 1);
    // Unmapped and mapped again, an address goes to the end of the order.
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::Can, 0, address(130, 1, 0, 9), 16, 9)).ok());
    ASSERT_EQ(map.unmapNode(5, address(130, 1, 0, 5)), Status::Ok);
    ASSERT_EQ(map.mapNode(5, address(130, 1, 0, 5)), Status::Ok);
    EXPECT_EQ(map.resolve(5, 9).value().interface, 1);
}

TEST(AddressMapTest, TheReverseMappingFindsASenderOnEachOfItsInterfaces)
{
    Map map;
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::Can, 0, address(130, 1, 0, 9), 16, 9)).ok());
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::Can, 1, address(130, 2, 0, 9), 16, 9)).ok());
    ASSERT_EQ(map.mapNode(5, address(130, 1, 0, 5)), Status::Ok);
    ASSERT_EQ(map.mapNode(5, address(130, 2, 0, 5)), Status::Ok);
    ASSERT_EQ(map.mapNode(6, address(130, 2, 0, 6)), Status::Ok);
    EXPECT_EQ(map.nodeAt(0, 5).status(), Status::NotFound) << "no neighbour has CAN node 5 yet";
    ASSERT_EQ(map.setPhysicalAddress(address(130, 1, 0, 5), 5), Status::Ok);
    ASSERT_EQ(map.setPhysicalAddress(address(130, 2, 0, 5), 7), Status::Ok);
    ASSERT_EQ(map.setPhysicalAddress(address(130, 2, 0, 6), 5), Status::Ok);
    EXPECT_EQ(map.nodeAt(0, 5).value(), 5);
    EXPECT_EQ(map.nodeAt(1, 7).value(), 5) << "the same node on its second bus, under another CAN node number";
    EXPECT_EQ(map.nodeAt(1, 5).value(), 6) << "CAN node 5 of the second bus is another node";
    EXPECT_EQ(map.nodeAt(0, 7).status(), Status::NotFound) << "CAN node 7 is on the second bus only";
    EXPECT_EQ(map.nodeAt(2, 5).status(), Status::NotFound) << "no interface 2";
    EXPECT_EQ(map.nodeAt(200, 5).status(), Status::NotFound);
    ASSERT_EQ(map.setPhysicalAddress(address(130, 1, 0, 4), 4), Status::Ok);
    EXPECT_EQ(map.nodeAt(0, 4).status(), Status::NotFound) << "a neighbour no node is mapped onto";
    ASSERT_EQ(map.unmapNode(5, address(130, 1, 0, 5)), Status::Ok);
    EXPECT_EQ(map.nodeAt(0, 5).status(), Status::NotFound);
    EXPECT_EQ(map.nodeAt(1, 7).value(), 5);
}

TEST(AddressMapTest, TheLongestRouteWins)
{
    Map map;
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::Can, 0, address(130, 1, 0, 9), 16, 9)).ok());
    ASSERT_EQ(map.setPhysicalAddress(address(130, 1, 0, 1), 1), Status::Ok);
    ASSERT_EQ(map.setPhysicalAddress(address(130, 1, 0, 2), 2), Status::Ok);
    ASSERT_EQ(map.addRoute(address(140, 0, 0, 0), 8, address(130, 1, 0, 1)), Status::Ok);
    ASSERT_EQ(map.addRoute(address(140, 7, 0, 0), 16, address(130, 1, 0, 2)), Status::Ok);
    ASSERT_EQ(map.mapNode(20, address(140, 7, 3, 4)), Status::Ok);
    ASSERT_EQ(map.mapNode(21, address(140, 8, 3, 4)), Status::Ok);
    EXPECT_EQ(map.resolve(20, 9).value().physical, 2u);
    EXPECT_EQ(map.resolve(21, 9).value().physical, 1u);
    ASSERT_EQ(map.removeRoute(address(140, 7, 0, 0), 16), Status::Ok);
    EXPECT_EQ(map.resolve(20, 9).value().physical, 1u);
    EXPECT_EQ(map.removeRoute(address(140, 7, 0, 0), 16), Status::NotFound);
}

TEST(AddressMapTest, EachRoutesGatewayIsNamedOnceWhereItIsReached)
{
    Map map;
    NextHop hops[Map::kRoutes];
    EXPECT_EQ(map.gatewayHops(hops), 0u) << "no routes";
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::Can, 0, address(130, 1, 0, 9), 16, 9)).ok());
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::Can, 1, address(130, 2, 0, 9), 16, 9)).ok());
    ASSERT_EQ(map.addRoute(address(140, 0, 0, 0), 8, address(130, 1, 0, 1)), Status::Ok);
    ASSERT_EQ(map.addRoute(address(141, 0, 0, 0), 8, address(130, 1, 0, 1)), Status::Ok);
    ASSERT_EQ(map.addRoute(address(142, 0, 0, 0), 8, address(130, 2, 0, 4)), Status::Ok);
    ASSERT_EQ(map.addRoute(address(143, 0, 0, 0), 8, address(142, 0, 0, 1)), Status::Ok);
    EXPECT_EQ(map.gatewayHops(hops), 0u) << "no gateway has a physical address yet";
    ASSERT_EQ(map.setPhysicalAddress(address(130, 1, 0, 1), 1), Status::Ok);
    ASSERT_EQ(map.setPhysicalAddress(address(130, 2, 0, 4), 4), Status::Ok);
    ASSERT_EQ(map.gatewayHops(hops), 2u) << "two routes through one gateway name it once; a gateway behind a "
                                            "route is not asked";
    EXPECT_EQ(hops[0].interface, 0);
    EXPECT_EQ(hops[0].physical, 1u);
    EXPECT_EQ(hops[1].interface, 1);
    EXPECT_EQ(hops[1].physical, 4u);
    ASSERT_EQ(map.removeInterface(1), Status::Ok);
    ASSERT_EQ(map.gatewayHops(hops), 1u) << "a gateway on a bus no longer attached";
    EXPECT_EQ(hops[0].physical, 1u);
}

TEST(AddressMapTest, EveryTablesErrors)
{
    Map map;
    ASSERT_TRUE(map.addInterface(interfaceOf(InterfaceKind::ModbusRtu, 0, address(130, 1, 0, 9), 16, 9)).ok());
    EXPECT_EQ(map.resolve(9, 9).status(), Status::InvalidArgument) << "the local node";
    EXPECT_EQ(map.resolve(4, 9).status(), Status::NotFound) << "a node mapped to nothing";
    EXPECT_EQ(map.mapNode(4, address(224, 0, 0, 1)), Status::InvalidArgument);
    EXPECT_EQ(map.mapNode(4, address(130, 255, 255, 255)), Status::InvalidArgument);
    ASSERT_EQ(map.mapNode(4, address(130, 1, 0, 4)), Status::Ok);
    EXPECT_EQ(map.mapNode(5, address(130, 1, 0, 4)), Status::AlreadyExists) << "one address, one node";
    EXPECT_EQ(map.unmapNode(5, address(130, 1, 0, 4)), Status::NotFound);
    EXPECT_EQ(map.setPhysicalAddress(address(131, 1, 0, 4), 4), Status::InvalidArgument) << "on no local subnet";
    EXPECT_EQ(map.setPhysicalAddress(address(130, 1, 0, 4), 248), Status::InvalidArgument) << "beyond Modbus";
    ASSERT_EQ(map.setPhysicalAddress(address(130, 1, 0, 4), 40), Status::Ok);
    ASSERT_EQ(map.setPhysicalAddress(address(130, 1, 0, 4), 4), Status::Ok) << "replaced";
    EXPECT_EQ(map.resolve(4, 9).value().physical, 4u);
    EXPECT_EQ(map.clearPhysicalAddress(address(130, 1, 0, 4)), Status::Ok);
    EXPECT_EQ(map.clearPhysicalAddress(address(130, 1, 0, 4)), Status::NotFound);
    EXPECT_EQ(map.resolve(4, 9).status(), Status::Unreachable);
    EXPECT_EQ(map.addRoute(address(140, 1, 0, 0), 8, address(130, 1, 0, 1)), Status::InvalidArgument)
        << "bits beyond the prefix";
    EXPECT_EQ(map.addRoute(address(140, 0, 0, 0), 8, address(224, 1, 0, 1)), Status::InvalidArgument);
    EXPECT_EQ(map.addRoute(address(140, 0, 0, 0), 40, address(130, 1, 0, 1)), Status::InvalidArgument);
    ASSERT_EQ(map.addRoute(address(140, 0, 0, 0), 8, address(130, 1, 0, 1)), Status::Ok);
    EXPECT_EQ(map.addRoute(address(140, 0, 0, 0), 8, address(130, 1, 0, 2)), Status::AlreadyExists);
    ASSERT_EQ(map.mapNode(30, address(140, 0, 0, 30)), Status::Ok);
    EXPECT_EQ(map.resolve(30, 9).status(), Status::Unreachable) << "the gateway has no physical address";
    // A route whose gateway is not on a local subnet leads nowhere.
    ASSERT_EQ(map.addRoute(address(150, 0, 0, 0), 8, address(140, 0, 0, 1)), Status::Ok);
    ASSERT_EQ(map.mapNode(31, address(150, 0, 0, 31)), Status::Ok);
    EXPECT_EQ(map.resolve(31, 9).status(), Status::Unreachable);
    // Full tables.
    for (uint8_t i = 0; i < Map::kNodeAddresses; ++i) {
        (void)map.mapNode(100, address(135, 0, 0, static_cast<uint8_t>(i + 1)));
    }
    EXPECT_EQ(map.mapNode(100, address(136, 0, 0, 1)), Status::TableFull);
    for (uint8_t i = 0; i < Map::kNeighbours; ++i) {
        (void)map.setPhysicalAddress(address(130, 1, 1, static_cast<uint8_t>(i + 1)), 1);
    }
    EXPECT_EQ(map.setPhysicalAddress(address(130, 1, 2, 1), 1), Status::TableFull);
    for (uint8_t i = 0; i < Map::kRoutes; ++i) {
        (void)map.addRoute(address(static_cast<uint8_t>(160 + i), 0, 0, 0), 8, address(130, 1, 0, 1));
    }
    EXPECT_EQ(map.addRoute(address(200, 0, 0, 0), 8, address(130, 1, 0, 1)), Status::TableFull);
}

namespace {

// An independent model of the tables and of resolution, written from the
// description in NetworkInterfacesManager.hpp with vectors and no capacities.
struct Model {
    struct Interface {
        uint8_t number;
        NetworkInterface value;
    };
    std::vector<Interface> interfaces;
    std::vector<std::pair<uint16_t, NetworkAddress>> nodes; // In mapping order.
    std::vector<std::pair<NetworkAddress, uint32_t>> neighbours;
    struct Route {
        NetworkAddress destination;
        uint8_t prefixLength;
        NetworkAddress gateway;
    };
    std::vector<Route> routes;

    std::optional<Interface> local(NetworkAddress a) const
    {
        std::optional<Interface> best;
        for (const Interface& i : interfaces) {
            if (a.isIn(i.value.address, i.value.prefixLength) && (!best || i.number < best->number)) {
                best = i;
            }
        }
        return best;
    }

    std::optional<NextHop> hop(NetworkAddress destination) const
    {
        NetworkAddress via = destination;
        std::optional<Interface> out = local(destination);
        if (!out) {
            const Route* best = nullptr;
            for (const Route& r : routes) {
                if (destination.isIn(r.destination, r.prefixLength) && (!best || r.prefixLength > best->prefixLength)) {
                    best = &r;
                }
            }
            if (best == nullptr) {
                return std::nullopt;
            }
            via = best->gateway;
            out = local(via);
            if (!out) {
                return std::nullopt;
            }
        }
        for (const auto& [a, physical] : neighbours) {
            if (a == via && dcos::isPhysicalAddressOf(out->value.kind, physical)) {
                return NextHop{out->number, physical, destination, via};
            }
        }
        return std::nullopt;
    }

    dcos::Result<NextHop> resolve(uint16_t node, uint16_t self) const
    {
        if (node == self) {
            return Status::InvalidArgument;
        }
        bool mapped = false;
        for (const auto& [n, a] : nodes) {
            if (n == node) {
                mapped = true;
                if (const std::optional<NextHop> h = hop(a)) {
                    return *h;
                }
            }
        }
        return mapped ? Status::Unreachable : Status::NotFound;
    }
};

} // namespace

TEST(AddressMapTest, ResolutionAgreesWithAModelUnderRandomTables)
{
    std::mt19937 random(7013);
    const auto pick = [&random](uint32_t n) { return static_cast<uint32_t>(random() % n); };
    // Few nets and hosts, so that addresses, subnets and routes collide often.
    const auto randomAddress = [&pick] {
        return address(static_cast<uint8_t>(130 + pick(3)), static_cast<uint8_t>(pick(3)), 0,
                       static_cast<uint8_t>(1 + pick(6)));
    };
    for (int round = 0; round < 200; ++round) {
        Map map;
        Model model;
        for (int step = 0; step < 60; ++step) {
            switch (pick(8)) {
            case 0: {
                const InterfaceKind kind = pick(2) == 0 ? InterfaceKind::Can : InterfaceKind::ModbusRtu;
                const NetworkInterface i =
                    interfaceOf(kind, static_cast<uint8_t>(pick(2)), randomAddress(), pick(2) == 0 ? 8 : 16, 1 + pick(3));
                const auto added = map.addInterface(i);
                if (added.ok()) {
                    model.interfaces.push_back({added.value(), i});
                }
                break;
            }
            case 1: {
                const uint8_t number = static_cast<uint8_t>(pick(4));
                if (map.removeInterface(number) == Status::Ok) {
                    std::erase_if(model.interfaces, [number](const Model::Interface& i) { return i.number == number; });
                }
                break;
            }
            case 2:
            case 3: {
                const uint16_t node = static_cast<uint16_t>(1 + pick(5));
                const NetworkAddress a = randomAddress();
                if (map.mapNode(node, a) == Status::Ok) {
                    model.nodes.emplace_back(node, a);
                }
                break;
            }
            case 4: {
                if (!model.nodes.empty()) {
                    const auto victim = model.nodes[pick(static_cast<uint32_t>(model.nodes.size()))];
                    ASSERT_EQ(map.unmapNode(victim.first, victim.second), Status::Ok);
                    std::erase(model.nodes, victim);
                }
                break;
            }
            case 5: {
                const NetworkAddress a = randomAddress();
                const uint32_t physical = 1 + pick(4);
                if (map.setPhysicalAddress(a, physical) == Status::Ok) {
                    std::erase_if(model.neighbours, [a](const auto& n) { return n.first == a; });
                    model.neighbours.emplace_back(a, physical);
                }
                break;
            }
            case 6: {
                const NetworkAddress a = randomAddress();
                if (map.clearPhysicalAddress(a) == Status::Ok) {
                    std::erase_if(model.neighbours, [a](const auto& n) { return n.first == a; });
                }
                break;
            }
            default: {
                const uint8_t prefixLength = pick(2) == 0 ? 8 : 16;
                const NetworkAddress destination(randomAddress().raw() & NetworkAddress::maskOf(prefixLength));
                const NetworkAddress gateway = randomAddress();
                if (pick(3) == 0) {
                    if (map.removeRoute(destination, prefixLength) == Status::Ok) {
                        std::erase_if(model.routes, [&](const Model::Route& r) {
                            return r.destination == destination && r.prefixLength == prefixLength;
                        });
                    }
                } else if (map.addRoute(destination, prefixLength, gateway) == Status::Ok) {
                    model.routes.push_back({destination, prefixLength, gateway});
                }
                break;
            }
            }
            for (uint16_t node = 0; node <= 6; ++node) {
                const auto expected = model.resolve(node, 6);
                const auto actual = map.resolve(node, 6);
                ASSERT_EQ(actual.status(), expected.status()) << "round " << round << " step " << step << " node " << node;
                if (expected.ok()) {
                    ASSERT_EQ(actual.value().interface, expected.value().interface);
                    ASSERT_EQ(actual.value().physical, expected.value().physical);
                    ASSERT_EQ(actual.value().destination, expected.value().destination);
                    ASSERT_EQ(actual.value().via, expected.value().via);
                }
            }
        }
    }
}
