// Kernel side of the system agent's device management (dissertation 7.3.2).
//
// The DeviceManager keeps the table of installed drivers and implements the
// primitives that dcos::SystemAgent forwards to it. Each slot holds a
// DeviceEntry: the driver object, the number of counted opens, and the number
// of calls into the driver in progress. The ObjectTable keeps the owner, the
// name and the visibility, and rejects forged and stale ids.
//
// Serialisation: the manager touches its table only with interrupts
// disabled, and for O(1) steps only. Calls into a driver run with interrupts
// in the state the caller had, so a long transfer does not delay interrupts;
// a call in progress is counted so that Delete refuses (Busy) to remove a
// driver that a preempted task is still inside. The bookkeeping after the
// call re-resolves the id, so a device removed meanwhile by resource
// recovery is simply skipped.
//
// The manager is constant-initialised (constexpr constructor), so it is
// usable before static constructors run and needs no start-up call: the
// initial eight slots are activated on the first Create or AddObjects, and
// the table takes the node id from localNode() whenever it is empty.
#pragma once

#include <dcos/Device.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/ObjectTable.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// The per-device state the system agent keeps beside the driver object.
struct DeviceEntry {
    /// The installed driver object; null only in a free slot.
    Device* device = nullptr;
    /// Opens that succeeded and have not been closed yet.
    uint32_t openCount = 0;
    /// Calls into the driver that have started and not yet returned.
    uint16_t callsInProgress = 0;
};

/// The object table type that holds the installed devices.
using DeviceTable = ObjectTable<DeviceEntry, kDeviceCapacity, TaskOwnerKeys>;

/// A consistent copy of one device's state, for listings such as the console.
struct DeviceInfo {
    /// The device's id.
    ObjectId id;
    /// The owning task, or null for a device owned by the system.
    ObjectId owner;
    /// The visibility the device was created with.
    Visibility visibility = Visibility::Local;
    /// Opens counted now.
    uint32_t openCount = 0;
    /// The device's name; empty for an unnamed device.
    char name[DeviceTable::kNameCapacity] = {};
};

/// The system agent's table of installed device drivers.
///
/// The public member functions named after seed primitives implement the
/// dcos::SystemAgent function of the same name, with the same checks and
/// errors; see dcos/SystemAgent.hpp for their contracts.
class DeviceManager {
public:
    /// Device slots reserved at build time; AddObjects activates them.
    static constexpr size_t kCapacity = kDeviceCapacity;
    /// Device slots active before any AddObjects.
    static constexpr size_t kInitialDevices = 8;
    /// Most opens counted on one device; one more Open fails with Busy.
    static constexpr uint32_t kMaxOpenCount = 0xFFFF;

    /// Creates an empty manager; constexpr so a static one is constant initialised.
    constexpr DeviceManager() : table_(ObjectType::Device, 0) {}

    DeviceManager(const DeviceManager&) = delete;
    DeviceManager& operator=(const DeviceManager&) = delete;

    /// Installs @p device for the calling task. Privileged. O(1).
    Result<ObjectId> Create(Device& device, const char* name, Visibility visibility);
    /// Removes a device that is neither open nor in use. Privileged. O(1).
    Status Delete(ObjectId id);
    /// Calls the driver's Probe. O(1) plus the driver.
    Status Probe(ObjectId id);
    /// Calls the driver's Open and counts it when it succeeds. O(1) plus the driver.
    Status Open(ObjectId id);
    /// Calls the driver's Close for a counted open. O(1) plus the driver.
    Status Close(ObjectId id);
    /// Calls the driver's Read on an open device. O(1) plus the driver.
    Result<size_t> Read(ObjectId id, uint32_t channel, void* buffer, size_t length);
    /// Calls the driver's Write on an open device. O(1) plus the driver.
    Result<size_t> Write(ObjectId id, uint32_t channel, const void* buffer, size_t length);
    /// Calls the driver's Control on an open device. O(1) plus the driver.
    Status Control(ObjectId id, uint32_t command, void* argument, size_t length);

    /// Finds a device visible from @p askingScope by name. Configuration service, O(N).
    ///
    /// The application interface asks with Visibility::Local; the network
    /// manager will ask with the scope of the node a lookup came from.
    Result<ObjectId> NameToObject(const char* name, Visibility askingScope);
    /// Activates @p count more slots. Privileged configuration service, O(count).
    Status AddObjects(size_t count);
    /// Transfers a device owned by the calling task to @p newOwner. O(1).
    Status XferOwnership(ObjectId id, ObjectId newOwner);

    /// Closes (once per counted open) and deletes every device owned by
    /// @p deadTask; returns how many were deleted. O(N).
    ///
    /// The task agent reaches this through recoverResourcesOf when a task
    /// ends. It runs with interrupts disabled throughout, which is bounded
    /// because drivers never block. A device whose driver a preempted task
    /// is still inside is deleted all the same: its owner is gone, and the
    /// driver object itself stays valid. Devices owned by the system (null
    /// owner) are never recovered.
    unsigned recoverDevicesOf(ObjectId deadTask);

    /// Copies the state of the device in slot @p slot into @p info; false
    /// when the slot is free or not active. O(1); for listings, which walk
    /// the slots from 0 to activeCount() - 1.
    bool snapshot(size_t slot, DeviceInfo& info);

    /// Number of active device slots, including the initial eight.
    size_t activeCount() const;
    /// Number of installed devices.
    size_t usedCount() const;

    /// The table as the object directory reads it (ObjectDirectory.hpp).
    ObjectTableView tableView() const { return table_.view(); }

private:
    size_t slotOf(ObjectId id) const { return table_.slotNumber(id); }

    // Applies the id checks common to every primitive; call with interrupts disabled.
    Result<DeviceEntry*> lookup(ObjectId id);
    // Activates the initial slots on first use; call with interrupts disabled.
    void start();
    // What a call into the driver needs from the device's state.
    enum class Call : uint8_t {
        Probe,    // Any installed device.
        Open,     // Fewer than kMaxOpenCount opens counted.
        Close,    // An open counted, which beginCall releases.
        Transfer, // An open counted (Read, Write, Control).
    };

    // Checks the id and the device's state for @p call and counts a call into the driver.
    Result<Device*> beginCall(ObjectId id, Call call);
    // Ends a call counted by beginCall, counting one more open when @p countOpen.
    void endCall(ObjectId id, bool countOpen);
    // Removes a resolved device from the table; call with interrupts disabled.
    void remove(ObjectId id, DeviceEntry& entry);

    DeviceTable table_;
    // The id of the device in each slot (null when free), so that listings
    // can walk the table without knowing slot generations.
    ObjectId ids_[kCapacity] = {};
    bool started_ = false;
};

/// The node's device manager, which the system agent interface uses.
DeviceManager& deviceManager();

} // namespace dcos::internal
