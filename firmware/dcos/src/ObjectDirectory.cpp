#include <dcos/internal/ObjectDirectory.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos::internal {

Result<ObjectTableView> objectTableOf(ObjectType type)
{
    switch (type) {
    case ObjectType::Task: return taskTableView();
    case ObjectType::Timer: return timerTableView();
    case ObjectType::Device: return deviceTableView();
    case ObjectType::BufferPool: return bufferPoolTableView();
    case ObjectType::Heap: return heapTableView();
    case ObjectType::MessagePort: return messagePortTableView();
    case ObjectType::DsmPublisher: return publisherTableView();
    case ObjectType::Semaphore: return semaphoreTableView();
    default: return Status::InvalidArgument;
    }
}

bool objectAt(const ObjectTableView& view, size_t slot, ObjectSummary& out)
{
    if (slot >= view.active) {
        return false;
    }
    // An agent may create or delete in this slot from another task or an
    // interrupt handler: the copy is taken whole, or not at all.
    arch_x86::InterruptGuard guard;
    const ObjectEntryHeader& header = view.header(slot);
    if (header.key == 0) {
        return false;
    }
    out.id = ObjectId::fromRaw(header.key);
    out.owner = header.owner;
    out.visibility = header.visibility;
    for (size_t i = 0; i < kObjectNameCapacity; ++i) {
        out.name[i] = header.name[i];
    }
    out.name[kObjectNameCapacity - 1] = '\0';
    return true;
}

bool slotOfObject(const ObjectTableView& view, ObjectId id, size_t& slot)
{
    for (size_t i = 0; i < view.active; ++i) {
        arch_x86::InterruptGuard guard;
        if (view.header(i).key == id.raw() && !id.isNull()) {
            slot = i;
            return true;
        }
    }
    return false;
}

} // namespace dcos::internal
