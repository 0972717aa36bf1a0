// Host tests for the system agent's device management (dissertation 7.3.2).
//
// Most tests drive a fresh DeviceManager of their own; the last ones go
// through the systemAgent interface object, resource recovery and the
// devices console command, which all use the node's manager, and leave it
// empty again. FakeKernelContext plays the calling task.
#include <dcos/Device.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/internal/DeviceManager.hpp>
#include <dcos/internal/ResourceRecovery.hpp>

#include <shell/Shell.hpp>

#include "FakeKernelContext.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

using dcos::Device;
using dcos::ObjectId;
using dcos::ObjectType;
using dcos::Result;
using dcos::Status;
using dcos::Visibility;
using dcos::internal::DeviceInfo;
using dcos::internal::DeviceManager;
using dcos::internal::DeviceTable;

namespace {

constexpr uint16_t kNode = dcos::fake::kDefaultNode;
const ObjectId kSuperUser(kNode, ObjectType::Task, 10);
const ObjectId kOtherSuperUser(kNode, ObjectType::Task, 11);
const ObjectId kUserTask(kNode, ObjectType::Task, 20);

// Control commands of the fake driver.
constexpr uint32_t kSetGain = 1;   // argument: uint32_t in
constexpr uint32_t kGetGain = 2;   // argument: uint32_t out
constexpr uint32_t kTrigger = 3;   // no argument

// A driver that records every call and answers as the test configures it.
// Read returns bytes from a per-channel store that Write fills.
class FakeDevice final : public Device {
public:
    int probes = 0;
    int opens = 0;
    int closes = 0;
    int reads = 0;
    int writes = 0;
    int controls = 0;
    int triggers = 0;
    uint32_t lastChannel = 0;
    uint32_t gain = 1;

    Status probeStatus = Status::Ok;
    Status openStatus = Status::Ok;
    Status closeStatus = Status::Ok;
    Status transferStatus = Status::Ok;
    // When set, Read and Write report this many bytes whatever the length.
    bool overrideCount = false;
    size_t countToReport = 0;
    // Runs inside Read, to act on the agent while a call is in progress.
    std::function<void()> duringRead;

private:
    Status Probe() override
    {
        ++probes;
        return probeStatus;
    }

    Status Open() override
    {
        ++opens;
        return openStatus;
    }

    Status Close() override
    {
        ++closes;
        return closeStatus;
    }

    Result<size_t> Read(uint32_t channel, void* buffer, size_t length) override
    {
        ++reads;
        lastChannel = channel;
        if (duringRead) {
            duringRead();
        }
        if (transferStatus != Status::Ok) {
            return transferStatus;
        }
        const std::string& data = store_[channel % 4];
        const size_t count = std::min(length, data.size());
        if (count != 0) {
            std::memcpy(buffer, data.data(), count);
        }
        return overrideCount ? countToReport : count;
    }

    Result<size_t> Write(uint32_t channel, const void* buffer, size_t length) override
    {
        ++writes;
        lastChannel = channel;
        if (transferStatus != Status::Ok) {
            return transferStatus;
        }
        // The device holds at most 8 bytes per channel.
        const size_t count = std::min<size_t>(length, 8);
        store_[channel % 4].assign(static_cast<const char*>(buffer), count);
        return overrideCount ? countToReport : count;
    }

    Status Control(uint32_t command, void* argument, size_t length) override
    {
        ++controls;
        switch (command) {
        case kSetGain:
            if (length != sizeof(uint32_t)) {
                return Status::InvalidArgument;
            }
            std::memcpy(&gain, argument, sizeof gain);
            return Status::Ok;
        case kGetGain:
            if (length != sizeof(uint32_t)) {
                return Status::InvalidArgument;
            }
            std::memcpy(argument, &gain, sizeof gain);
            return Status::Ok;
        case kTrigger:
            if (argument != nullptr || length != 0) {
                return Status::InvalidArgument;
            }
            ++triggers;
            return Status::Ok;
        default:
            return Status::NotSupported;
        }
    }

    std::string store_[4];
};

// A driver that overrides only what it must, to check the defaults.
class ProbeOnlyDevice final : public Device {
private:
    Status Probe() override { return Status::Ok; }
};

class DeviceManagerTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        dcos::fake::reset();
        dcos::fake::playSuperUser(kSuperUser);
    }

    void TearDown() override { dcos::fake::reset(); }

    ObjectId create(Device& device, const char* name = nullptr, Visibility visibility = Visibility::Local)
    {
        const Result<ObjectId> id = manager.Create(device, name, visibility);
        EXPECT_TRUE(id.ok()) << dcos::statusName(id.status());
        return id.value();
    }

    // The state the agent shows for id, found by walking the slots as the console does.
    DeviceInfo infoOf(ObjectId id)
    {
        for (size_t slot = 0; slot < manager.activeCount(); ++slot) {
            DeviceInfo info;
            if (manager.snapshot(slot, info) && info.id == id) {
                return info;
            }
        }
        ADD_FAILURE() << "device " << std::hex << id.raw() << " not listed";
        return DeviceInfo{};
    }

    // Every primitive that takes an id answers @p expected for @p id.
    void expectEveryPrimitiveRefuses(ObjectId id, Status expected)
    {
        char buffer[4] = {};
        uint32_t value = 0;
        EXPECT_EQ(manager.Probe(id), expected);
        EXPECT_EQ(manager.Open(id), expected);
        EXPECT_EQ(manager.Close(id), expected);
        EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).status(), expected);
        EXPECT_EQ(manager.Write(id, 0, buffer, sizeof buffer).status(), expected);
        EXPECT_EQ(manager.Control(id, kGetGain, &value, sizeof value), expected);
        EXPECT_EQ(manager.XferOwnership(id, kUserTask), expected);
        EXPECT_EQ(manager.Delete(id), expected);
    }

    DeviceManager manager;
};

} // namespace

TEST_F(DeviceManagerTest, CreateNeedsSuperUser)
{
    FakeDevice device;
    dcos::fake::playUserTask(kUserTask);
    EXPECT_EQ(manager.Create(device, "adc0", Visibility::Local).status(), Status::NotPermitted);
    EXPECT_EQ(manager.usedCount(), 0u);
    EXPECT_TRUE(device.id().isNull());
}

TEST_F(DeviceManagerTest, CreateIsRefusedInInterruptContext)
{
    FakeDevice device;
    dcos::fake::setInInterrupt(true);
    EXPECT_EQ(manager.Create(device, "adc0", Visibility::Local).status(), Status::InInterrupt);
    EXPECT_EQ(manager.usedCount(), 0u);
}

TEST_F(DeviceManagerTest, CreateIssuesADeviceIdOwnedByTheCaller)
{
    FakeDevice device;
    const ObjectId id = create(device, "adc0", Visibility::Regional);
    EXPECT_EQ(id.type(), ObjectType::Device);
    EXPECT_EQ(id.node(), kNode);
    EXPECT_EQ(device.id(), id);
    EXPECT_EQ(manager.usedCount(), 1u);
    const DeviceInfo info = infoOf(id);
    EXPECT_EQ(info.owner, kSuperUser);
    EXPECT_EQ(info.visibility, Visibility::Regional);
    EXPECT_EQ(info.openCount, 0u);
    EXPECT_STREQ(info.name, "adc0");
    // Installing calls no driver function.
    EXPECT_EQ(device.probes + device.opens, 0);
}

TEST_F(DeviceManagerTest, CreateStampsTheLocalNodeWhileTheTableIsEmpty)
{
    FakeDevice first;
    FakeDevice second;
    dcos::fake::setLocalNode(7);
    const ObjectId id = create(first);
    EXPECT_EQ(id.node(), 7);
    EXPECT_EQ(manager.Probe(id), Status::Ok);
    ASSERT_EQ(manager.Delete(id), Status::Ok);
    dcos::fake::setLocalNode(9);
    const ObjectId renumbered = create(second);
    EXPECT_EQ(renumbered.node(), 9);
    EXPECT_EQ(manager.Probe(renumbered), Status::Ok);
}

TEST_F(DeviceManagerTest, TheSameDriverObjectCannotBeInstalledTwice)
{
    FakeDevice device;
    const ObjectId id = create(device, "adc0");
    EXPECT_EQ(manager.Create(device, "adc1", Visibility::Local).status(), Status::AlreadyExists);
    EXPECT_EQ(manager.usedCount(), 1u);
    EXPECT_EQ(device.id(), id);
}

TEST_F(DeviceManagerTest, CreateRejectsBadNamesAndVisibility)
{
    FakeDevice device;
    EXPECT_EQ(manager.Create(device, "sixteen-chars-xx", Visibility::Local).status(), Status::InvalidArgument);
    EXPECT_EQ(manager.Create(device, "ok", static_cast<Visibility>(3)).status(), Status::InvalidArgument);
    EXPECT_EQ(manager.usedCount(), 0u);
    EXPECT_TRUE(device.id().isNull());
    EXPECT_TRUE(manager.Create(device, "fifteen-chars-x", Visibility::Local).ok());
}

TEST_F(DeviceManagerTest, EightSlotsAreActiveThenTableFullUntilAddObjects)
{
    EXPECT_EQ(manager.activeCount(), DeviceManager::kInitialDevices);
    std::vector<FakeDevice> devices(DeviceManager::kCapacity + 1);
    for (size_t i = 0; i < 8; ++i) {
        create(devices[i]);
    }
    EXPECT_EQ(manager.Create(devices[8], nullptr, Visibility::Local).status(), Status::TableFull);
    EXPECT_TRUE(devices[8].id().isNull());

    dcos::fake::playUserTask(kUserTask);
    EXPECT_EQ(manager.AddObjects(8), Status::NotPermitted);
    dcos::fake::playSuperUser(kSuperUser);
    dcos::fake::setInInterrupt(true);
    EXPECT_EQ(manager.AddObjects(8), Status::InInterrupt);
    dcos::fake::setInInterrupt(false);
    EXPECT_EQ(manager.AddObjects(0), Status::InvalidArgument);
    EXPECT_EQ(manager.AddObjects(4), Status::InvalidArgument);
    EXPECT_EQ(manager.activeCount(), 8u);

    EXPECT_EQ(manager.AddObjects(8), Status::Ok);
    EXPECT_EQ(manager.activeCount(), 16u);
    create(devices[8]);
    EXPECT_EQ(manager.AddObjects(DeviceManager::kCapacity), Status::TableFull);
    EXPECT_EQ(manager.AddObjects(DeviceManager::kCapacity - 16), Status::Ok);
    EXPECT_EQ(manager.activeCount(), DeviceManager::kCapacity);
    EXPECT_EQ(manager.AddObjects(8), Status::TableFull);
    for (size_t i = 9; i < DeviceManager::kCapacity; ++i) {
        create(devices[i]);
    }
    EXPECT_EQ(manager.usedCount(), DeviceManager::kCapacity);
    EXPECT_EQ(manager.Create(devices[DeviceManager::kCapacity], nullptr, Visibility::Local).status(),
              Status::TableFull);
}

TEST_F(DeviceManagerTest, AddObjectsBeforeTheFirstCreateKeepsTheInitialEight)
{
    EXPECT_EQ(manager.AddObjects(8), Status::Ok);
    EXPECT_EQ(manager.activeCount(), 16u);
    std::vector<FakeDevice> devices(17);
    for (size_t i = 0; i < 16; ++i) {
        create(devices[i]);
    }
    EXPECT_EQ(manager.Create(devices[16], nullptr, Visibility::Local).status(), Status::TableFull);
}

TEST_F(DeviceManagerTest, DeleteNeedsSuperUserButNotOwnership)
{
    FakeDevice device;
    const ObjectId id = create(device);
    dcos::fake::playUserTask(kUserTask);
    EXPECT_EQ(manager.Delete(id), Status::NotPermitted);
    dcos::fake::playSuperUser(kOtherSuperUser);
    dcos::fake::setInInterrupt(true);
    EXPECT_EQ(manager.Delete(id), Status::InInterrupt);
    dcos::fake::setInInterrupt(false);
    EXPECT_EQ(manager.usedCount(), 1u);
    EXPECT_EQ(manager.Delete(id), Status::Ok);
    EXPECT_EQ(manager.usedCount(), 0u);
    EXPECT_TRUE(device.id().isNull());
}

TEST_F(DeviceManagerTest, DeletedIdsTurnStaleEvenAfterTheSlotIsReused)
{
    FakeDevice device;
    const ObjectId old = create(device, "adc0");
    ASSERT_EQ(manager.Delete(old), Status::Ok);
    expectEveryPrimitiveRefuses(old, Status::StaleId);
    EXPECT_EQ(manager.NameToObject("adc0", Visibility::Local).status(), Status::NotFound);

    // Fill every active slot, so the old one is taken again: freed slots are
    // reused last, so the last device created lands in it.
    std::vector<FakeDevice> others(DeviceManager::kInitialDevices);
    ObjectId reused;
    for (FakeDevice& other : others) {
        reused = create(other);
        ASSERT_FALSE(reused.isNull());
    }
    EXPECT_NE(reused, old);
    expectEveryPrimitiveRefuses(old, Status::StaleId);
    EXPECT_EQ(manager.Probe(reused), Status::Ok);
    // The deleted driver object is free to be installed again.
    ASSERT_EQ(manager.AddObjects(8), Status::Ok);
    EXPECT_TRUE(manager.Create(device, "adc0", Visibility::Local).ok());
}

TEST_F(DeviceManagerTest, ForgedIdsAreRefused)
{
    FakeDevice device;
    const ObjectId id = create(device);
    expectEveryPrimitiveRefuses(ObjectId::null(), Status::InvalidId);
    expectEveryPrimitiveRefuses(ObjectId(kNode, ObjectType::Semaphore, id.index()), Status::WrongType);
    expectEveryPrimitiveRefuses(ObjectId(kNode, ObjectType::Task, id.index()), Status::WrongType);
    // Indices the table never handed out.
    expectEveryPrimitiveRefuses(ObjectId(kNode, ObjectType::Device, 20), Status::InvalidId);
    expectEveryPrimitiveRefuses(ObjectId(kNode, ObjectType::Device, static_cast<uint16_t>(id.index() + 1)),
                                Status::InvalidId);
    // An index handed out before, whose device was deleted.
    FakeDevice other;
    const ObjectId gone = create(other);
    ASSERT_EQ(manager.Delete(gone), Status::Ok);
    expectEveryPrimitiveRefuses(gone, Status::StaleId);
    // None of this touched the real device.
    EXPECT_EQ(device.probes + device.opens + device.closes + device.reads + device.writes + device.controls, 0);
    EXPECT_EQ(manager.Probe(id), Status::Ok);
}

TEST_F(DeviceManagerTest, IdsOfOtherNodesAreRemote)
{
    FakeDevice device;
    const ObjectId id = create(device);
    const ObjectId remote(kNode + 1, ObjectType::Device, id.index());
    expectEveryPrimitiveRefuses(remote, Status::Remote);
    EXPECT_EQ(device.probes + device.opens + device.reads, 0);
    EXPECT_EQ(manager.usedCount(), 1u);
}

TEST_F(DeviceManagerTest, ProbeReturnsTheDriversStatusOpenOrNot)
{
    FakeDevice device;
    const ObjectId id = create(device);
    EXPECT_EQ(manager.Probe(id), Status::Ok);
    device.probeStatus = Status::NotFound;
    EXPECT_EQ(manager.Probe(id), Status::NotFound);
    device.probeStatus = Status::Corrupted;
    ASSERT_EQ(manager.Open(id), Status::Ok);
    EXPECT_EQ(manager.Probe(id), Status::Corrupted);
    EXPECT_EQ(device.probes, 3);
}

TEST_F(DeviceManagerTest, OpensAreCountedAndEachCloseUndoesOne)
{
    FakeDevice device;
    const ObjectId id = create(device);
    EXPECT_EQ(manager.Open(id), Status::Ok);
    EXPECT_EQ(manager.Open(id), Status::Ok);
    EXPECT_EQ(device.opens, 2);
    EXPECT_EQ(infoOf(id).openCount, 2u);
    EXPECT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(infoOf(id).openCount, 1u);
    EXPECT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(infoOf(id).openCount, 0u);
    EXPECT_EQ(device.closes, 2);
    EXPECT_EQ(manager.Close(id), Status::NotOpen);
    EXPECT_EQ(device.closes, 2);
}

TEST_F(DeviceManagerTest, CloseWithoutOpenIsRefusedWithoutCallingTheDriver)
{
    FakeDevice device;
    const ObjectId id = create(device);
    EXPECT_EQ(manager.Close(id), Status::NotOpen);
    EXPECT_EQ(device.closes, 0);
}

TEST_F(DeviceManagerTest, AFailedOpenIsNotCounted)
{
    FakeDevice device;
    const ObjectId id = create(device);
    device.openStatus = Status::NotFound;
    EXPECT_EQ(manager.Open(id), Status::NotFound);
    EXPECT_EQ(infoOf(id).openCount, 0u);
    char buffer[2];
    EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).status(), Status::NotOpen);
    EXPECT_EQ(manager.Close(id), Status::NotOpen);
    EXPECT_EQ(manager.Delete(id), Status::Ok);
}

TEST_F(DeviceManagerTest, AFailedCloseLeavesTheDeviceOpen)
{
    FakeDevice device;
    const ObjectId id = create(device);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    device.closeStatus = Status::Busy;
    EXPECT_EQ(manager.Close(id), Status::Busy);
    EXPECT_EQ(infoOf(id).openCount, 1u);
    EXPECT_EQ(manager.Delete(id), Status::Busy);
    device.closeStatus = Status::Ok;
    EXPECT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(manager.Delete(id), Status::Ok);
}

TEST_F(DeviceManagerTest, OpenStopsAtTheOpenLimit)
{
    FakeDevice device;
    const ObjectId id = create(device);
    for (uint32_t i = 0; i < DeviceManager::kMaxOpenCount; ++i) {
        ASSERT_EQ(manager.Open(id), Status::Ok) << i;
    }
    EXPECT_EQ(manager.Open(id), Status::Busy);
    EXPECT_EQ(static_cast<uint32_t>(device.opens), DeviceManager::kMaxOpenCount);
    EXPECT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(manager.Open(id), Status::Ok);
}

TEST_F(DeviceManagerTest, ReadWriteAndControlNeedAnOpenDevice)
{
    FakeDevice device;
    const ObjectId id = create(device);
    char buffer[4] = {};
    uint32_t value = 5;
    EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).status(), Status::NotOpen);
    EXPECT_EQ(manager.Write(id, 0, buffer, sizeof buffer).status(), Status::NotOpen);
    EXPECT_EQ(manager.Control(id, kSetGain, &value, sizeof value), Status::NotOpen);
    EXPECT_EQ(device.reads + device.writes + device.controls, 0);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    ASSERT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).status(), Status::NotOpen);
    EXPECT_EQ(device.reads, 0);
}

TEST_F(DeviceManagerTest, ReadAndWriteMoveDataOnAChannel)
{
    FakeDevice device;
    const ObjectId id = create(device);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    const char out[] = "0123456789";
    const Result<size_t> written = manager.Write(id, 2, out, 10);
    ASSERT_TRUE(written.ok());
    EXPECT_EQ(written.value(), 8u); // The device accepts eight bytes per channel.
    EXPECT_EQ(device.lastChannel, 2u);

    char in[16] = {};
    const Result<size_t> read = manager.Read(id, 2, in, sizeof in);
    ASSERT_TRUE(read.ok());
    EXPECT_EQ(read.value(), 8u);
    EXPECT_EQ(std::string(in, 8), "01234567");
    EXPECT_EQ(manager.Read(id, 1, in, sizeof in).value(), 0u); // Nothing waiting on channel 1.
    EXPECT_EQ(device.lastChannel, 1u);
}

TEST_F(DeviceManagerTest, ControlPassesTheArgumentBothWays)
{
    FakeDevice device;
    const ObjectId id = create(device);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    uint32_t gain = 40;
    EXPECT_EQ(manager.Control(id, kSetGain, &gain, sizeof gain), Status::Ok);
    EXPECT_EQ(device.gain, 40u);
    uint32_t readBack = 0;
    EXPECT_EQ(manager.Control(id, kGetGain, &readBack, sizeof readBack), Status::Ok);
    EXPECT_EQ(readBack, 40u);
    EXPECT_EQ(manager.Control(id, kTrigger, nullptr, 0), Status::Ok);
    EXPECT_EQ(device.triggers, 1);
}

TEST_F(DeviceManagerTest, NullBuffersWithALengthAreRefusedBeforeTheDriver)
{
    FakeDevice device;
    const ObjectId id = create(device);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    EXPECT_EQ(manager.Read(id, 0, nullptr, 4).status(), Status::InvalidArgument);
    EXPECT_EQ(manager.Write(id, 0, nullptr, 4).status(), Status::InvalidArgument);
    EXPECT_EQ(manager.Control(id, kSetGain, nullptr, 4), Status::InvalidArgument);
    EXPECT_EQ(device.reads + device.writes + device.controls, 0);
    // An empty transfer is the driver's to judge.
    EXPECT_EQ(manager.Read(id, 0, nullptr, 0).value(), 0u);
    EXPECT_EQ(manager.Write(id, 0, nullptr, 0).value(), 0u);
    EXPECT_EQ(device.reads + device.writes, 2);
}

TEST_F(DeviceManagerTest, DriverErrorsReachTheCaller)
{
    FakeDevice device;
    const ObjectId id = create(device);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    char buffer[4] = {};
    device.transferStatus = Status::Timeout;
    EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).status(), Status::Timeout);
    device.transferStatus = Status::NoMemory;
    EXPECT_EQ(manager.Write(id, 0, buffer, sizeof buffer).status(), Status::NoMemory);
    uint16_t tooSmall = 0;
    EXPECT_EQ(manager.Control(id, kSetGain, &tooSmall, sizeof tooSmall), Status::InvalidArgument);
    EXPECT_EQ(manager.Control(id, 99, nullptr, 0), Status::NotSupported);
    EXPECT_EQ(device.reads + device.writes + device.controls, 4);
    // Errors leave the device open and usable.
    device.transferStatus = Status::Ok;
    EXPECT_TRUE(manager.Write(id, 0, buffer, sizeof buffer).ok());
}

TEST_F(DeviceManagerTest, ADriverReportingMoreBytesThanTheBufferIsCorrupted)
{
    FakeDevice device;
    const ObjectId id = create(device);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    char buffer[4] = {};
    device.overrideCount = true;
    device.countToReport = 5;
    EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).status(), Status::Corrupted);
    EXPECT_EQ(manager.Write(id, 0, buffer, sizeof buffer).status(), Status::Corrupted);
    device.countToReport = 4;
    EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).value(), 4u);
}

TEST_F(DeviceManagerTest, DefaultDriverFunctions)
{
    ProbeOnlyDevice device;
    const ObjectId id = create(device);
    char buffer[4] = {};
    EXPECT_EQ(manager.Probe(id), Status::Ok);
    EXPECT_EQ(manager.Open(id), Status::Ok);
    EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).status(), Status::NotSupported);
    EXPECT_EQ(manager.Write(id, 0, buffer, sizeof buffer).status(), Status::NotSupported);
    EXPECT_EQ(manager.Control(id, 1, nullptr, 0), Status::NotSupported);
    EXPECT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(manager.Delete(id), Status::Ok);
}

TEST_F(DeviceManagerTest, UserTasksUseDevicesButCannotRemoveThem)
{
    FakeDevice device;
    const ObjectId id = create(device, "dac0");
    dcos::fake::playUserTask(kUserTask);
    const Result<ObjectId> found = manager.NameToObject("dac0", Visibility::Local);
    ASSERT_TRUE(found.ok());
    EXPECT_EQ(found.value(), id);
    char buffer[2] = {'a', 'b'};
    EXPECT_EQ(manager.Probe(id), Status::Ok);
    EXPECT_EQ(manager.Open(id), Status::Ok);
    EXPECT_EQ(manager.Write(id, 0, buffer, sizeof buffer).value(), 2u);
    EXPECT_EQ(manager.Read(id, 0, buffer, sizeof buffer).value(), 2u);
    EXPECT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(manager.Delete(id), Status::NotPermitted);
    EXPECT_EQ(manager.XferOwnership(id, kUserTask), Status::NotOwner);
}

TEST_F(DeviceManagerTest, InterruptHandlersMayCallTheTransferPrimitivesOnly)
{
    FakeDevice device;
    const ObjectId id = create(device, "adc0");
    dcos::fake::setInInterrupt(true);
    char buffer[2] = {'x', 'y'};
    uint32_t gain = 3;
    EXPECT_EQ(manager.Probe(id), Status::Ok);
    EXPECT_EQ(manager.Open(id), Status::Ok);
    EXPECT_EQ(manager.Write(id, 1, buffer, sizeof buffer).value(), 2u);
    EXPECT_EQ(manager.Read(id, 1, buffer, sizeof buffer).value(), 2u);
    EXPECT_EQ(manager.Control(id, kSetGain, &gain, sizeof gain), Status::Ok);
    EXPECT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(manager.NameToObject("adc0", Visibility::Local).status(), Status::InInterrupt);
    EXPECT_EQ(manager.XferOwnership(id, kUserTask), Status::InInterrupt);
    EXPECT_EQ(manager.Delete(id), Status::InInterrupt);
    dcos::fake::setInInterrupt(false);
    EXPECT_EQ(manager.Delete(id), Status::Ok);
}

TEST_F(DeviceManagerTest, DeleteIsRefusedWhileOpen)
{
    FakeDevice device;
    const ObjectId id = create(device);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    EXPECT_EQ(manager.Delete(id), Status::Busy);
    EXPECT_EQ(manager.Probe(id), Status::Ok);
    ASSERT_EQ(manager.Close(id), Status::Ok);
    EXPECT_EQ(manager.Delete(id), Status::Ok);
}

TEST_F(DeviceManagerTest, DeleteIsRefusedWhileACallIsInTheDriver)
{
    FakeDevice device;
    const ObjectId id = create(device);
    ASSERT_EQ(manager.Open(id), Status::Ok);
    // A task is inside Read when it is preempted by another that closes the
    // device and tries to remove it; the driver runs the second task's calls.
    Status duringCall = Status::Ok;
    Status closeDuringCall = Status::Ok;
    device.duringRead = [&] {
        closeDuringCall = manager.Close(id);
        duringCall = manager.Delete(id);
    };
    char buffer[1];
    EXPECT_TRUE(manager.Read(id, 0, buffer, sizeof buffer).ok());
    EXPECT_EQ(closeDuringCall, Status::Ok);
    EXPECT_EQ(duringCall, Status::Busy);
    // Once the call has returned the device can go.
    EXPECT_EQ(manager.Delete(id), Status::Ok);
}

TEST_F(DeviceManagerTest, NameToObjectFindsNamedDevicesVisibleFromTheScope)
{
    FakeDevice local;
    FakeDevice regional;
    FakeDevice unnamed;
    const ObjectId localId = create(local, "can0", Visibility::Local);
    const ObjectId regionalId = create(regional, "dio0", Visibility::Regional);
    create(unnamed);
    EXPECT_EQ(manager.NameToObject("can0", Visibility::Local).value(), localId);
    EXPECT_EQ(manager.NameToObject("dio0", Visibility::Local).value(), regionalId);
    EXPECT_EQ(manager.NameToObject("dio0", Visibility::Regional).value(), regionalId);
    EXPECT_EQ(manager.NameToObject("can0", Visibility::Regional).status(), Status::NotFound);
    EXPECT_EQ(manager.NameToObject("dio0", Visibility::Global).status(), Status::NotFound);
    EXPECT_EQ(manager.NameToObject("", Visibility::Local).status(), Status::NotFound);
    EXPECT_EQ(manager.NameToObject(nullptr, Visibility::Local).status(), Status::NotFound);
    EXPECT_EQ(manager.NameToObject("can", Visibility::Local).status(), Status::NotFound);
}

TEST_F(DeviceManagerTest, XferOwnershipMovesTheDeviceToAnotherTaskOrTheSystem)
{
    FakeDevice device;
    const ObjectId id = create(device);
    EXPECT_EQ(manager.XferOwnership(id, ObjectId(kNode, ObjectType::Semaphore, 1)), Status::InvalidArgument);
    EXPECT_EQ(manager.XferOwnership(id, kUserTask), Status::Ok);
    EXPECT_EQ(infoOf(id).owner, kUserTask);
    EXPECT_EQ(manager.XferOwnership(id, kSuperUser), Status::NotOwner);
    dcos::fake::playUserTask(kUserTask);
    EXPECT_EQ(manager.XferOwnership(id, ObjectId::null()), Status::Ok);
    EXPECT_TRUE(infoOf(id).owner.isNull());
    // Devices owned by the system survive every task.
    EXPECT_EQ(manager.recoverDevicesOf(kUserTask), 0u);
    EXPECT_EQ(manager.recoverDevicesOf(kSuperUser), 0u);
    EXPECT_EQ(manager.recoverDevicesOf(ObjectId::null()), 0u);
    EXPECT_EQ(manager.usedCount(), 1u);
}

TEST_F(DeviceManagerTest, RecoveryClosesAndDeletesOnlyTheDeadTasksDevices)
{
    FakeDevice openTwice;
    FakeDevice closed;
    FakeDevice others;
    const ObjectId a = create(openTwice, "a");
    const ObjectId b = create(closed, "b");
    dcos::fake::playSuperUser(kOtherSuperUser);
    const ObjectId c = create(others, "c");
    ASSERT_EQ(manager.Open(a), Status::Ok);
    ASSERT_EQ(manager.Open(a), Status::Ok);
    ASSERT_EQ(manager.Open(c), Status::Ok);
    openTwice.closeStatus = Status::Busy; // Ignored: the owner is gone.

    EXPECT_EQ(manager.recoverDevicesOf(kSuperUser), 2u);
    EXPECT_EQ(openTwice.closes, 2);
    EXPECT_EQ(closed.closes, 0);
    EXPECT_EQ(manager.Probe(a), Status::StaleId);
    EXPECT_EQ(manager.Probe(b), Status::StaleId);
    EXPECT_TRUE(openTwice.id().isNull());
    EXPECT_TRUE(closed.id().isNull());
    EXPECT_EQ(manager.NameToObject("a", Visibility::Local).status(), Status::NotFound);
    // The other task's device is untouched and still open.
    EXPECT_EQ(manager.usedCount(), 1u);
    EXPECT_EQ(others.closes, 0);
    EXPECT_EQ(infoOf(c).openCount, 1u);
    EXPECT_EQ(manager.NameToObject("c", Visibility::Local).value(), c);
    EXPECT_EQ(manager.recoverDevicesOf(kSuperUser), 0u);
}

TEST_F(DeviceManagerTest, RecoveryDuringADriverCallLeavesTheTableConsistent)
{
    FakeDevice device;
    const ObjectId id = create(device);
    // A user task is inside Read when the owner dies and recovery runs.
    ASSERT_EQ(manager.Open(id), Status::Ok);
    unsigned recovered = 0;
    device.duringRead = [&] { recovered = manager.recoverDevicesOf(kSuperUser); };
    char buffer[1];
    EXPECT_TRUE(manager.Read(id, 0, buffer, sizeof buffer).ok());
    EXPECT_EQ(recovered, 1u);
    EXPECT_EQ(device.closes, 1);
    EXPECT_EQ(manager.usedCount(), 0u);
    EXPECT_EQ(manager.Probe(id), Status::StaleId);
    // The slot's next device starts with no call in progress: it can be deleted at once.
    std::vector<FakeDevice> next(DeviceManager::kInitialDevices);
    for (FakeDevice& each : next) {
        const ObjectId nextId = create(each);
        EXPECT_EQ(manager.Delete(nextId), Status::Ok);
    }
}

TEST_F(DeviceManagerTest, SnapshotSkipsFreeAndInactiveSlots)
{
    FakeDevice device;
    DeviceInfo info;
    EXPECT_FALSE(manager.snapshot(0, info));
    const ObjectId id = create(device, "x");
    size_t listed = 0;
    for (size_t slot = 0; slot < DeviceManager::kCapacity + 4; ++slot) {
        if (manager.snapshot(slot, info)) {
            ++listed;
            EXPECT_EQ(info.id, id);
        }
    }
    EXPECT_EQ(listed, 1u);
}

// The interface object, the registered recovery and the console command
// share the node's manager; each test leaves it empty.
namespace {

class StringSink final : public runtime::CharacterSink {
public:
    void put(char character) override { text += character; }
    std::string text;
};

class DeviceSystemAgentTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        dcos::fake::reset();
        dcos::fake::playSuperUser(kSuperUser);
        ASSERT_EQ(dcos::internal::deviceManager().usedCount(), 0u);
    }

    void TearDown() override
    {
        EXPECT_EQ(dcos::internal::deviceManager().usedCount(), 0u);
        dcos::fake::reset();
    }
};

} // namespace

TEST_F(DeviceSystemAgentTest, TheInterfaceObjectReachesTheNodesManager)
{
    using dcos::systemAgent;
    FakeDevice device;
    const Result<ObjectId> id = systemAgent.Create(device, "adc0", Visibility::Local);
    ASSERT_TRUE(id.ok());
    EXPECT_EQ(dcos::internal::deviceManager().usedCount(), 1u);
    EXPECT_EQ(systemAgent.NameToObject("adc0").value(), id.value());
    EXPECT_EQ(systemAgent.Probe(id.value()), Status::Ok);
    EXPECT_EQ(systemAgent.Read(id.value(), 0, nullptr, 0).status(), Status::NotOpen);
    EXPECT_EQ(systemAgent.Open(id.value()), Status::Ok);
    const char out[3] = {'1', '2', '3'};
    char in[3] = {};
    uint32_t gain = 7;
    EXPECT_EQ(systemAgent.Write(id.value(), 3, out, sizeof out).value(), 3u);
    EXPECT_EQ(systemAgent.Read(id.value(), 3, in, sizeof in).value(), 3u);
    EXPECT_EQ(std::string(in, 3), "123");
    EXPECT_EQ(systemAgent.Control(id.value(), kSetGain, &gain, sizeof gain), Status::Ok);
    EXPECT_EQ(device.gain, 7u);
    EXPECT_EQ(systemAgent.Delete(id.value()), Status::Busy);
    EXPECT_EQ(systemAgent.Close(id.value()), Status::Ok);
    EXPECT_EQ(systemAgent.XferOwnership(id.value(), kOtherSuperUser), Status::Ok);
    dcos::fake::playUserTask(kUserTask);
    EXPECT_EQ(systemAgent.AddObjects(8), Status::NotPermitted);
    EXPECT_EQ(systemAgent.Delete(id.value()), Status::NotPermitted);
    dcos::fake::playSuperUser(kSuperUser);
    EXPECT_EQ(systemAgent.Delete(id.value()), Status::Ok);
    EXPECT_EQ(systemAgent.Probe(id.value()), Status::StaleId);
}

TEST_F(DeviceSystemAgentTest, ResourceRecoveryDeletesTheDeadTasksDevices)
{
    const ObjectId deadTask(kNode, ObjectType::Task, 0x123);
    FakeDevice mine;
    FakeDevice survivor;
    dcos::fake::playSuperUser(deadTask);
    const ObjectId mineId = dcos::systemAgent.Create(mine, "mine", Visibility::Local).value();
    ASSERT_EQ(dcos::systemAgent.Open(mineId), Status::Ok);
    dcos::fake::playSuperUser(kSuperUser);
    const ObjectId survivorId = dcos::systemAgent.Create(survivor, "survivor", Visibility::Local).value();

    EXPECT_EQ(dcos::internal::recoverResourcesOf(deadTask), 1u);
    EXPECT_EQ(mine.closes, 1);
    EXPECT_EQ(dcos::systemAgent.Probe(mineId), Status::StaleId);
    EXPECT_EQ(dcos::systemAgent.Probe(survivorId), Status::Ok);
    EXPECT_EQ(dcos::systemAgent.Delete(survivorId), Status::Ok);
}

TEST_F(DeviceSystemAgentTest, DevicesCommandListsIdNameOpenCountAndOwner)
{
    FakeDevice named;
    FakeDevice unnamed;
    dcos::fake::setLocalNode(2);
    const ObjectId namedId = dcos::systemAgent.Create(named, "adc0", Visibility::Global).value();
    const ObjectId unnamedId = dcos::systemAgent.Create(unnamed, nullptr, Visibility::Local).value();
    ASSERT_EQ(dcos::systemAgent.Open(namedId), Status::Ok);
    ASSERT_EQ(dcos::systemAgent.Open(namedId), Status::Ok);
    ASSERT_EQ(dcos::systemAgent.XferOwnership(unnamedId, ObjectId::null()), Status::Ok);

    StringSink out;
    shell::Shell shell(out, "> ");
    char line[] = "devices";
    EXPECT_EQ(shell.execute(line), shell::CommandResult::Ok);
    char namedRow[80];
    std::snprintf(namedRow, sizeof namedRow, "0x%08x  adc0                2  0x%08x  global\r\n", namedId.raw(),
                  kSuperUser.raw());
    char unnamedRow[80];
    std::snprintf(unnamedRow, sizeof unnamedRow, "0x%08x  -                   0  system      local\r\n", unnamedId.raw());
    // Rows come in slot order, which depends on the slots earlier tests freed.
    const std::string header = "id          name             open  owner       visibility\r\n";
    const std::string footer = "2 of 8 device slots used, 64 reserved\r\n";
    const bool namedFirst = (namedId.index() & (DeviceManager::kCapacity - 1))
                            < (unnamedId.index() & (DeviceManager::kCapacity - 1));
    EXPECT_EQ(out.text, header + (namedFirst ? std::string(namedRow) + unnamedRow : std::string(unnamedRow) + namedRow)
                            + footer);

    StringSink usageOut;
    shell::Shell usageShell(usageOut, "> ");
    char bad[] = "devices all";
    EXPECT_EQ(usageShell.execute(bad), shell::CommandResult::UsageError);
    EXPECT_EQ(usageOut.text, "usage: devices\r\n");

    ASSERT_EQ(dcos::systemAgent.Close(namedId), Status::Ok);
    ASSERT_EQ(dcos::systemAgent.Close(namedId), Status::Ok);
    EXPECT_EQ(dcos::systemAgent.Delete(namedId), Status::Ok);
    EXPECT_EQ(dcos::systemAgent.Delete(unnamedId), Status::Ok);
}
