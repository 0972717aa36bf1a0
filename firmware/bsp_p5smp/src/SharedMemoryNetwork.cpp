// The dual-Pentium board's own network between its two nodes, brought up by
// the root task (dcos::internal::boardNetworkStart): one interface of kind
// SharedMemory on each node, 130.3.0.<node>/16, physical address the
// processor, carried by a SharedMemoryLink, and the other node mapped and
// its physical address set, so that a primitive given the other node's id
// goes over it at once. The console command `shm` shows the link's counts
// (SharedMemoryCommands.cpp).
#include <bsp/P5smpBoard.hpp>
#include <bsp/SharedMemoryLink.hpp>

#include <bsp/Board.hpp>
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/internal/NetworkBootHooks.hpp>
#include <runtime/Format.hpp>

namespace {

bsp::SharedMemoryLink link;

// The shared-memory network's addresses: 130.3.0.<node>/16, after the CAN
// channels' 130.1 and 130.2 (docs/guide/network-tables.md).
dcos::NetworkAddress addressOf(uint16_t node)
{
    return dcos::NetworkAddress::fromOctets(130, 3, static_cast<uint8_t>(node >> 8), static_cast<uint8_t>(node));
}
constexpr uint8_t kPrefixLength = 16;

} // namespace

namespace bsp {

const SharedMemoryLink& boardSharedMemoryLink() { return link; }

} // namespace bsp

namespace dcos::internal {

void boardNetworkStart()
{
    runtime::CharacterSink& out = bsp::console();
    if (!bsp::otherNodeRunning()) {
        return; // One node on the board: nothing to reach.
    }
    const uint16_t self = bsp::nodeId();
    const uint16_t other = bsp::otherNodeId();
    const uint32_t physical = bsp::processorIndex();
    const Result<uint8_t> added = NetworkInterfacesManager::AddInterface(InterfaceKind::SharedMemory, 0,
                                                                          addressOf(self), kPrefixLength, physical);
    Status status = added.status();
    if (status == Status::Ok) {
        status = NetworkInterfacesManager::MapNode(other, addressOf(other));
    }
    if (status == Status::Ok) {
        status = NetworkInterfacesManager::SetPhysicalAddress(addressOf(other), physical ^ 1u);
    }
    if (status == Status::Ok) {
        status = NetworkInterfacesManager::AttachLink(added.value(), link);
    }
    if (status != Status::Ok) {
        runtime::format(out, "shared-memory network not started: %s\r\n", statusName(status));
        return;
    }
    runtime::format(out, "shared-memory network: interface %u, 130.3.%u.%u/16, physical %lu; node %u at physical %lu\r\n",
                    unsigned(added.value()), unsigned(self >> 8), unsigned(self & 0xFF),
                    static_cast<unsigned long>(physical), unsigned(other), static_cast<unsigned long>(physical ^ 1u));
}

} // namespace dcos::internal
