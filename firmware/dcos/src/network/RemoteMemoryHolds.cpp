// What other nodes hold of this node's pools and heaps (RemoteMemoryHolds.hpp).
#include <dcos/internal/RemoteMemoryHolds.hpp>

namespace dcos::internal {

size_t RemoteMemoryHolds::find(ObjectId area, uint32_t address) const
{
    for (size_t i = 0; i < kCapacity; ++i) {
        if (used_[i] && holds_[i].area == area && holds_[i].address == address) {
            return i;
        }
    }
    return kCapacity;
}

bool RemoteMemoryHolds::add(ObjectId area, uint32_t address, uint16_t node)
{
    for (size_t i = 0; i < kCapacity; ++i) {
        if (!used_[i]) {
            holds_[i] = Hold{area, address, node};
            used_[i] = true;
            ++count_;
            return true;
        }
    }
    return false;
}

Status RemoteMemoryHolds::check(ObjectId area, uint32_t address, uint16_t node) const
{
    const size_t slot = find(area, address);
    if (slot == kCapacity) {
        return Status::InvalidArgument;
    }
    return holds_[slot].node == node ? Status::Ok : Status::NotOwner;
}

void RemoteMemoryHolds::remove(ObjectId area, uint32_t address)
{
    const size_t slot = find(area, address);
    if (slot != kCapacity) {
        used_[slot] = false;
        --count_;
    }
}

size_t RemoteMemoryHolds::takeHoldsOf(uint16_t node, Hold* out, size_t room)
{
    size_t taken = 0;
    for (size_t i = 0; i < kCapacity && taken < room; ++i) {
        if (used_[i] && holds_[i].node == node) {
            out[taken++] = holds_[i];
            used_[i] = false;
            --count_;
        }
    }
    return taken;
}

} // namespace dcos::internal
