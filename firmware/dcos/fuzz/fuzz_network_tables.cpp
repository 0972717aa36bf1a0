// Fuzz target: the network interfaces manager's address parser and tables
// (seed 7.13), driven by arbitrary bytes.
//
// The input's first part, up to a zero byte, is parsed as an address text
// (what the console's "net" command reads): a text it accepts must format
// back into the same text. The rest is a program of table operations with
// arguments from a small space of addresses, so that subnets, routes and
// neighbours collide. Checks: every refusal is one of the documented
// statuses; Resolve never names an interface that does not exist, a
// physical address its kind cannot have, or a destination that is not one
// of the node's mapped addresses; and a node resolved directly goes to its
// own address.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <dcos/NetworkAddress.hpp>
#include <dcos/internal/AddressMap.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace {

using dcos::InterfaceKind;
using dcos::NetworkAddress;
using dcos::NetworkInterface;
using dcos::Status;

using Map = dcos::internal::AddressMap<dcos::internal::AddressMapCapacities{4, 8, 8, 4}>;

NetworkAddress addressFrom(fuzz::InputReader& in)
{
    // Nets 126 to 133 and 224 (not unicast), subnets 0 to 3, hosts 0 to 7 and 255.
    const unsigned char a = in.byte();
    const uint8_t net = (a & 0x0F) == 0x0F ? 224 : static_cast<uint8_t>(126 + (a & 7));
    const uint8_t host = (a & 0x80) != 0 ? 255 : static_cast<uint8_t>((a >> 4) & 7);
    return NetworkAddress::fromOctets(net, static_cast<uint8_t>(in.byte() & 3), 0, host);
}

bool documented(Status status)
{
    switch (status) {
    case Status::Ok:
    case Status::InvalidArgument:
    case Status::AlreadyExists:
    case Status::TableFull:
    case Status::NotFound:
    case Status::Unreachable: return true;
    default: return false;
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const unsigned char* data, std::size_t size)
{
    const unsigned char* zero = static_cast<const unsigned char*>(std::memchr(data, 0, size));
    const std::size_t textSize = zero != nullptr ? static_cast<std::size_t>(zero - data) : size;
    const std::string text(reinterpret_cast<const char*>(data), textSize);
    NetworkAddress parsed;
    if (NetworkAddress::parse(text.c_str(), parsed)) {
        char back[NetworkAddress::kTextSize];
        parsed.format(back);
        FUZZ_CHECK(text == back);
    }

    fuzz::InputReader in(data + textSize, size - textSize);
    Map map;
    while (!in.empty()) {
        const unsigned char operation = in.byte();
        Status status = Status::Ok;
        switch (operation % 8) {
        case 0: {
            NetworkInterface interface;
            interface.kind = static_cast<InterfaceKind>(in.byte() % 3);
            interface.channel = in.byte() & 1;
            interface.address = addressFrom(in);
            interface.prefixLength = static_cast<uint8_t>(in.byte() % 40);
            interface.physical = in.byte();
            status = map.addInterface(interface).status();
            break;
        }
        case 1: status = map.removeInterface(in.byte() & 7); break;
        case 2: status = map.mapNode(in.byte() & 7, addressFrom(in)); break;
        case 3: status = map.unmapNode(in.byte() & 7, addressFrom(in)); break;
        case 4: {
            const NetworkAddress address = addressFrom(in);
            status = map.setPhysicalAddress(address, in.byte());
            break;
        }
        case 5: status = map.clearPhysicalAddress(addressFrom(in)); break;
        case 6: {
            const NetworkAddress destination = addressFrom(in);
            const uint8_t prefixLength = static_cast<uint8_t>(in.byte() % 40);
            status = map.addRoute(destination, prefixLength, addressFrom(in));
            break;
        }
        default: {
            const NetworkAddress destination = addressFrom(in);
            status = map.removeRoute(destination, static_cast<uint8_t>(in.byte() % 40));
            break;
        }
        }
        FUZZ_CHECK(documented(status));
        for (uint16_t node = 0; node < 8; ++node) {
            const dcos::Result<dcos::NextHop> hop = map.resolve(node, 7);
            FUZZ_CHECK(documented(hop.status()));
            if (!hop.ok()) {
                FUZZ_CHECK(node != 7 || hop.status() == Status::InvalidArgument);
                continue;
            }
            const dcos::Result<NetworkInterface> out = map.interface(hop.value().interface);
            FUZZ_CHECK(out.ok());
            FUZZ_CHECK(dcos::isPhysicalAddressOf(out.value().kind, hop.value().physical));
            FUZZ_CHECK(hop.value().via.isIn(out.value().address, out.value().prefixLength));
            bool mapped = false;
            map.forEachNodeAddress([&](const Map::NodeAddress& entry) {
                mapped = mapped || (entry.node == node && entry.address == hop.value().destination);
            });
            FUZZ_CHECK(mapped);
            if (hop.value().destination.isIn(out.value().address, out.value().prefixLength)) {
                FUZZ_CHECK(hop.value().via == hop.value().destination);
            }
        }
    }
    return 0;
}
