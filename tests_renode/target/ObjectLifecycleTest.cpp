// Object ids and resource recovery on the target: KillTask and Delete give
// back everything a task owned, a full table is refused clearly, forged and
// stale ids are rejected (seed 6.4, 7.6).
#include "KernelTestSupport.hpp"

#include <dcos/Device.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/DeviceManager.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/StackArena.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::ObjectType;
using dcos::Status;
using dcos::systemAgent;
using dcos::taskAgent;
using dcos::timerAgent;

// A device with no hardware, so a task can own one.
class NullDevice final : public dcos::Device {
private:
    dcos::Status Probe() override { return dcos::Status::Ok; }
};

size_t deviceCount();

NullDevice nullDevices[2];
volatile bool ownerReady = false;
volatile size_t timersWhileOwned = 0;
volatile size_t devicesWhileOwned = 0;
ObjectId ownedTimers[3];
ObjectId ownedDevice;

void owningEntry(uintptr_t deviceIndex)
{
    for (ObjectId& timer : ownedTimers) {
        timer = timerAgent.Create(nullptr, dcos::Visibility::Local).value();
    }
    (void)timerAgent.SetPeriodicAlarm(ownedTimers[0], 5000000, dcos::AlarmNotification::event(1));
    ownedDevice = systemAgent.Create(nullDevices[deviceIndex], "null", dcos::Visibility::Local).value();
    (void)systemAgent.Open(ownedDevice);
    timersWhileOwned = dcos::internal::TimerManager::timerCount();
    devicesWhileOwned = deviceCount();
    ownerReady = !ownedTimers[0].isNull() && !ownedTimers[1].isNull() && !ownedTimers[2].isNull() &&
                 !ownedDevice.isNull();
    if (deviceIndex == 1) {
        (void)taskAgent.Delete(); // Suicide with everything still owned.
    }
    (void)taskAgent.ReceiveEvent(1u << 20, dcos::EventWait::Any, dcos::kWaitForever);
}

size_t deviceCount() { return dcos::internal::deviceManager().usedCount(); }

bool recovery(shell::Shell& shell)
{
    bool ok = true;
    for (uintptr_t variant = 0; variant < 2; ++variant) {
        const size_t tasksBefore = dcos::internal::TaskManager::taskCount();
        const size_t timersBefore = dcos::internal::TimerManager::timerCount();
        const size_t stackBefore = dcos::internal::StackArena::freeBytes();
        const size_t devicesBefore = deviceCount();
        ownerReady = false;
        // Installing a driver is privileged, so the owner is a super user.
        dcos::TaskAttributes attributes;
        attributes.name = variant == 0 ? "owner-killed" : "owner-suicide";
        attributes.priority = 10;
        attributes.superUser = true;
        const ObjectId owner = taskAgent.Create(attributes, owningEntry, variant).value();
        ok = check(shell, !owner.isNull() && ownerReady, "the owner created its objects") && ok;
        ok = check(shell, timersWhileOwned == timersBefore + 3, "three timers existed") && ok;
        ok = check(shell, devicesWhileOwned == devicesBefore + 1, "one device existed") && ok;
        if (variant == 0) {
            ok = checkStatus(shell, taskAgent.KillTask(owner), Status::Ok, "KillTask") && ok;
        } else {
            (void)taskAgent.SleepFor(2000000); // Let the reaper free the suicide's stack.
        }
        shell.print("%s: tasks %u->%u, timers %u->%u, devices %u->%u, stack arena %u->%u bytes free\r\n",
                    variant == 0 ? "KillTask" : "Delete", static_cast<unsigned>(tasksBefore),
                    static_cast<unsigned>(dcos::internal::TaskManager::taskCount()), static_cast<unsigned>(timersBefore),
                    static_cast<unsigned>(dcos::internal::TimerManager::timerCount()),
                    static_cast<unsigned>(devicesBefore), static_cast<unsigned>(deviceCount()),
                    static_cast<unsigned>(stackBefore), static_cast<unsigned>(dcos::internal::StackArena::freeBytes()));
        ok = check(shell, dcos::internal::TaskManager::taskCount() == tasksBefore, "the task slot came back") && ok;
        ok = check(shell, dcos::internal::TimerManager::timerCount() == timersBefore, "the timers came back") && ok;
        ok = check(shell, deviceCount() == devicesBefore, "the device came back") && ok;
        ok = check(shell, dcos::internal::StackArena::freeBytes() == stackBefore, "the stack came back") && ok;
        for (const ObjectId& timer : ownedTimers) {
            ok = checkStatus(shell, timerAgent.CancelAlarm(timer), Status::StaleId, "a recovered timer's id is stale") && ok;
        }
        ok = checkStatus(shell, taskAgent.Suspend(owner), Status::StaleId, "the dead task's id is stale") && ok;
    }
    return ok;
}

DCOS_TARGET_TEST(recoveryTest, "recovery", "KillTask and Delete recover every object the task owned", recovery);

void waitForeverEntry(uintptr_t) { (void)taskAgent.ReceiveEvent(1u << 20, dcos::EventWait::Any, dcos::kWaitForever); }

bool fullTable(shell::Shell& shell)
{
    ObjectId created[256];
    size_t count = 0;
    Status last = Status::Ok;
    dcos::TaskAttributes attributes;
    attributes.priority = 30;
    attributes.stackSize = dcos::kMinimumStackSize;
    while (count < 256) {
        const dcos::Result<ObjectId> id = taskAgent.Create(attributes, waitForeverEntry, 0);
        if (!id.ok()) {
            last = id.status();
            break;
        }
        created[count++] = id.value();
    }
    shell.print("created %u tasks, then: %s\r\n", static_cast<unsigned>(count), dcos::statusName(last));
    bool ok = checkStatus(shell, last, Status::TableFull, "a full task table");
    ok = checkStatus(shell, taskAgent.AddObjects(8), Status::Ok, "AddObjects(8)") && ok;
    size_t more = 0;
    while (more < 8 && count < 256) {
        const dcos::Result<ObjectId> id = taskAgent.Create(attributes, waitForeverEntry, 0);
        if (!id.ok()) {
            break;
        }
        created[count++] = id.value();
        ++more;
    }
    ok = check(shell, more == 8, "AddObjects made room for eight more") && ok;
    ok = checkStatus(shell, taskAgent.AddObjects(5), Status::InvalidArgument, "AddObjects needs groups of eight") && ok;
    for (size_t i = 0; i < count; ++i) {
        (void)taskAgent.KillTask(created[i]);
    }
    // Argument errors.
    attributes.priority = 32;
    ok = checkStatus(shell, taskAgent.Create(attributes, waitForeverEntry, 0).status(), Status::InvalidArgument,
                     "priority 32") && ok;
    attributes.priority = 30;
    attributes.stackSize = 100;
    ok = checkStatus(shell, taskAgent.Create(attributes, waitForeverEntry, 0).status(), Status::InvalidArgument,
                     "a stack below the minimum") && ok;
    attributes.stackSize = dcos::internal::StackArena::largestFreeBlock(); // No room left for its guard page.
    ok = checkStatus(shell, taskAgent.Create(attributes, waitForeverEntry, 0).status(), Status::NoMemory,
                     "a stack larger than the free arena") && ok;
    return ok;
}

DCOS_TARGET_TEST(fullTableTest, "fulltable", "a full task table gives TableFull until AddObjects", fullTable);

bool forgedIds(shell::Shell& shell)
{
    const uint16_t node = dcos::internal::localNode();
    const ObjectId self = taskAgent.IdOfSelf();
    bool ok = checkStatus(shell, taskAgent.Suspend(ObjectId(node, ObjectType::Task, 0x0FF)), Status::InvalidId,
                          "an unused slot");
    ok = checkStatus(shell, taskAgent.Suspend(ObjectId(node, ObjectType::Task, 0xFFF)), Status::InvalidId,
                     "an index beyond the table") && ok;
    ok = checkStatus(shell, taskAgent.Suspend(ObjectId(node, ObjectType::Timer, self.index())), Status::WrongType,
                     "a task's index with the timer type") && ok;
    ok = checkStatus(shell, taskAgent.Suspend(ObjectId(static_cast<uint16_t>(node + 1), ObjectType::Task, self.index())),
                     Status::Remote, "another node's task") && ok;
    ok = checkStatus(shell, taskAgent.Suspend(ObjectId::null()), Status::InvalidId, "the null id") && ok;
    // The null and the all-ones id on the task agent's inline lookup; the
    // other agents' fast paths are checked by "oddids" (OddIdFastPathTest.cpp).
    ok = checkStatus(shell, taskAgent.PostEvent(ObjectId::null(), 1), Status::InvalidId, "PostEvent to the null id") && ok;
    ok = checkStatus(shell, taskAgent.PostEvent(ObjectId::fromRaw(0xFFFFFFFFu), 1), Status::WrongType,
                     "PostEvent to the all-ones id") && ok;
    // A stale id: the generation bits of a deleted task's id no longer match.
    const ObjectId gone = spawn("short-lived", 10, waitForeverEntry);
    (void)taskAgent.KillTask(gone);
    const ObjectId reuse = spawn("reused", 30, waitForeverEntry);
    ok = checkStatus(shell, taskAgent.Suspend(gone), Status::StaleId, "a deleted task's id") && ok;
    ok = checkStatus(shell, taskAgent.KillTask(reuse), Status::Ok, "the live task is untouched") && ok;
    shell.print("ids: self %08lx, deleted %08lx, reused slot %08lx\r\n", static_cast<unsigned long>(self.raw()),
                static_cast<unsigned long>(gone.raw()), static_cast<unsigned long>(reuse.raw()));
    return ok;
}

DCOS_TARGET_TEST(forgedIdTest, "forgedid", "forged, foreign, mistyped and stale ids are rejected", forgedIds);

} // namespace

} // namespace target_test
