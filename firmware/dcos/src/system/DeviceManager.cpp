// The system agent's device management (dissertation 7.3.2): the kernel-side
// DeviceManager, the SystemAgent interface functions that forward to it, and
// the agent's resource recovery.
#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/DeviceManager.hpp>

#include <dcos/SystemAgent.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/ResourceRecovery.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos::internal {

namespace {

// The agent's bookkeeping runs with interrupts disabled, because interrupt
// handlers may call the device primitives too. Every critical section is O(1)
// except the configuration services and resource recovery.
using Lock = arch_x86::InterruptGuard;

constinit DeviceManager nodeDeviceManager;

} // namespace

DeviceManager& deviceManager()
{
    return nodeDeviceManager;
}

Result<DeviceEntry*> DeviceManager::lookup(ObjectId id)
{
    // The table gives InvalidId, WrongType, Remote and StaleId once it has
    // taken this node's id.
    start();
    return table_.resolve(id);
}

void DeviceManager::start()
{
    if (!started_) {
        // Cannot fail: the table is empty and kInitialDevices is a multiple
        // of eight below the capacity, which the static_assert below proves.
        (void)table_.AddObjects(kInitialDevices);
        started_ = true;
    }
    if (table_.usedCount() == 0 && table_.node() != localNode()) {
        (void)table_.setNode(localNode());
    }
}

static_assert(DeviceManager::kInitialDevices % DeviceTable::kGroupSize == 0
                  && DeviceManager::kInitialDevices <= DeviceManager::kCapacity,
              "the initial device slots must be a group count the table can hold");

void DeviceManager::remove(ObjectId id, DeviceEntry& entry)
{
    entry.device->installedAs_ = ObjectId::null();
    ids_[slotOf(id)] = ObjectId::null();
    (void)table_.Delete(id);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> DeviceManager::Create(Device& device, const char* name, Visibility visibility)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    const ObjectId owner = currentTaskId();
    Lock lock;
    if (!device.installedAs_.isNull()) {
        return Status::AlreadyExists;
    }
    start();
    const Result<ObjectId> id = table_.Create(owner, name, visibility);
    if (!id.ok()) {
        return id;
    }
    DeviceEntry* entry = table_.resolve(id.value()).value();
    entry->device = &device;
    device.installedAs_ = id.value();
    ids_[slotOf(id.value())] = id.value();
    return id;
}

DCOS_CONFIGURATION_SERVICE Status DeviceManager::Delete(ObjectId id)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    Lock lock;
    const Result<DeviceEntry*> entry = lookup(id);
    if (!entry.ok()) {
        return entry.status();
    }
    if (entry.value()->openCount != 0 || entry.value()->callsInProgress != 0) {
        return Status::Busy;
    }
    remove(id, *entry.value());
    return Status::Ok;
}

Result<Device*> DeviceManager::beginCall(ObjectId id, Call call)
{
    Lock lock;
    const Result<DeviceEntry*> entry = lookup(id);
    if (!entry.ok()) {
        return entry.status();
    }
    DeviceEntry& device = *entry.value();
    if ((call == Call::Close || call == Call::Transfer) && device.openCount == 0) {
        return Status::NotOpen;
    }
    // Opens are counted only when they succeed, so concurrent Opens can each
    // pass this check; the count is 32 bits wide, so the few that can be in
    // flight at once never overflow it.
    if ((call == Call::Open && device.openCount >= kMaxOpenCount) || device.callsInProgress == UINT16_MAX) {
        return Status::Busy;
    }
    if (call == Call::Close) {
        // The open is released before the driver runs, so that two Close
        // calls racing for the last open cannot both reach the driver.
        --device.openCount;
    }
    ++device.callsInProgress;
    return device.device;
}

void DeviceManager::endCall(ObjectId id, bool countOpen)
{
    Lock lock;
    // The id was valid when the call began; it fails to resolve now only when
    // resource recovery removed the device meanwhile, which leaves nothing to count.
    const Result<DeviceEntry*> entry = table_.resolve(id);
    if (entry.ok()) {
        --entry.value()->callsInProgress;
        if (countOpen) {
            ++entry.value()->openCount;
        }
    }
}

Status DeviceManager::Probe(ObjectId id)
{
    const Result<Device*> device = beginCall(id, Call::Probe);
    if (!device.ok()) {
        return device.status();
    }
    const Status status = device.value()->Probe();
    endCall(id, false);
    return status;
}

DCOS_CONFIGURATION_SERVICE Status DeviceManager::Open(ObjectId id)
{
    const Result<Device*> device = beginCall(id, Call::Open);
    if (!device.ok()) {
        return device.status();
    }
    const Status status = device.value()->Open();
    endCall(id, status == Status::Ok);
    return status;
}

DCOS_CONFIGURATION_SERVICE Status DeviceManager::Close(ObjectId id)
{
    const Result<Device*> device = beginCall(id, Call::Close);
    if (!device.ok()) {
        return device.status();
    }
    const Status status = device.value()->Close();
    // A refused Close leaves the device open: the open released by beginCall is counted again.
    endCall(id, status != Status::Ok);
    return status;
}

Result<size_t> DeviceManager::Read(ObjectId id, uint32_t channel, void* buffer, size_t length)
{
    if (buffer == nullptr && length != 0) {
        return Status::InvalidArgument;
    }
    const Result<Device*> device = beginCall(id, Call::Transfer);
    if (!device.ok()) {
        return device.status();
    }
    const Result<size_t> transferred = device.value()->Read(channel, buffer, length);
    endCall(id, false);
    if (transferred.ok() && transferred.value() > length) {
        return Status::Corrupted;
    }
    return transferred;
}

Result<size_t> DeviceManager::Write(ObjectId id, uint32_t channel, const void* buffer, size_t length)
{
    if (buffer == nullptr && length != 0) {
        return Status::InvalidArgument;
    }
    const Result<Device*> device = beginCall(id, Call::Transfer);
    if (!device.ok()) {
        return device.status();
    }
    const Result<size_t> transferred = device.value()->Write(channel, buffer, length);
    endCall(id, false);
    if (transferred.ok() && transferred.value() > length) {
        return Status::Corrupted;
    }
    return transferred;
}

Status DeviceManager::Control(ObjectId id, uint32_t command, void* argument, size_t length)
{
    if (argument == nullptr && length != 0) {
        return Status::InvalidArgument;
    }
    const Result<Device*> device = beginCall(id, Call::Transfer);
    if (!device.ok()) {
        return device.status();
    }
    const Status status = device.value()->Control(command, argument, length);
    endCall(id, false);
    return status;
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> DeviceManager::NameToObject(const char* name, Visibility askingScope)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    Lock lock;
    return table_.NameToObject(name, askingScope);
}

DCOS_CONFIGURATION_SERVICE Status DeviceManager::AddObjects(size_t count)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    Lock lock;
    start();
    return table_.AddObjects(count);
}

DCOS_CONFIGURATION_SERVICE Status DeviceManager::XferOwnership(ObjectId id, ObjectId newOwner)
{
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    const ObjectId caller = currentTaskId();
    Lock lock;
    const Result<DeviceEntry*> entry = lookup(id);
    if (!entry.ok()) {
        return entry.status();
    }
    return table_.XferOwnership(id, caller, newOwner);
}

DCOS_CONFIGURATION_SERVICE unsigned DeviceManager::recoverDevicesOf(ObjectId deadTask)
{
    if (deadTask.isNull()) {
        return 0;
    }
    Lock lock;
    const size_t recovered = table_.forEachOwnedBy(deadTask, [this](ObjectId id, DeviceEntry& entry) {
        // The status of each Close is ignored: the owner is gone and the
        // device is removed whatever the driver answers.
        for (; entry.openCount != 0; --entry.openCount) {
            (void)entry.device->Close();
        }
        remove(id, entry);
    });
    return static_cast<unsigned>(recovered);
}

// Cold: only the console's device listing reads it.
[[gnu::cold]] bool DeviceManager::snapshot(size_t slot, DeviceInfo& info)
{
    if (slot >= kCapacity) {
        return false;
    }
    Lock lock;
    const ObjectId id = ids_[slot];
    if (id.isNull()) {
        return false;
    }
    // The three look-ups cannot fail: ids_ holds only ids of installed devices.
    info.id = id;
    info.owner = table_.ownerOf(id).value();
    info.visibility = table_.visibilityOf(id).value();
    const char* name = table_.nameOf(id).value();
    size_t i = 0;
    for (; i + 1 < sizeof info.name && name[i] != '\0'; ++i) {
        info.name[i] = name[i];
    }
    info.name[i] = '\0';
    info.openCount = table_.resolve(id).value()->openCount;
    return true;
}

size_t DeviceManager::activeCount() const
{
    return started_ ? table_.activeCount() : kInitialDevices;
}

size_t DeviceManager::usedCount() const
{
    return table_.usedCount();
}

namespace {

unsigned recoverDevices(ObjectId deadTask)
{
    return deviceManager().recoverDevicesOf(deadTask);
}

} // namespace

DCOS_RESOURCE_RECOVERY(deviceRecovery, "system agent: devices", recoverDevices);

ObjectTableView deviceTableView()
{
    return deviceManager().tableView();
}

} // namespace dcos::internal

namespace dcos {

// The interface functions forward to the node's manager. When tasks run in
// ring 3 these become the trap stubs, and ids of other nodes will be routed
// to the network manager here instead of being refused with Remote.

DCOS_CONFIGURATION_SERVICE Result<ObjectId> SystemAgent::Create(Device& device, const char* name, Visibility visibility)
{
    return internal::deviceManager().Create(device, name, visibility);
}

DCOS_CONFIGURATION_SERVICE Status SystemAgent::Delete(ObjectId device)
{
    return internal::deviceManager().Delete(device);
}

Status SystemAgent::Probe(ObjectId device)
{
    return internal::deviceManager().Probe(device);
}

DCOS_CONFIGURATION_SERVICE Status SystemAgent::Open(ObjectId device)
{
    return internal::deviceManager().Open(device);
}

DCOS_CONFIGURATION_SERVICE Status SystemAgent::Close(ObjectId device)
{
    return internal::deviceManager().Close(device);
}

Result<size_t> SystemAgent::Read(ObjectId device, uint32_t channel, void* buffer, size_t length)
{
    return internal::deviceManager().Read(device, channel, buffer, length);
}

Result<size_t> SystemAgent::Write(ObjectId device, uint32_t channel, const void* buffer, size_t length)
{
    return internal::deviceManager().Write(device, channel, buffer, length);
}

Status SystemAgent::Control(ObjectId device, uint32_t command, void* argument, size_t length)
{
    return internal::deviceManager().Control(device, command, argument, length);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> SystemAgent::NameToObject(const char* name)
{
    return internal::orRemoteName(internal::deviceManager().NameToObject(name, Visibility::Local), ObjectType::Device,
                                  name);
}

DCOS_CONFIGURATION_SERVICE Status SystemAgent::AddObjects(size_t count)
{
    return internal::deviceManager().AddObjects(count);
}

DCOS_CONFIGURATION_SERVICE Status SystemAgent::XferOwnership(ObjectId device, ObjectId newOwner)
{
    return internal::deviceManager().XferOwnership(device, newOwner);
}

} // namespace dcos
