// A deleted object's id stays stale for as long as 12 bits allow.
//
// The 12-bit index of an id used to carry a slot number and a few
// generation bits, so a semaphore's id named a new semaphore again after
// 496 create/delete cycles (ports 1,024, timers 512, tasks 960). Every
// table now hands out all 4,096 index values before a freed one comes back
// (ObjectTable.hpp): these tests cycle each kind of object well past the old
// limits and check that the first id never answers again before then.
#include "KernelTestSupport.hpp"

#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace {

using namespace target_test;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

// Objects of the table that are alive through the whole cycle (the kernel's
// own among them) bring the bound down from 4,096; 3,000 cycles stay well
// below it and far above every old limit.
constexpr unsigned kCycles = 3000;

template <typename CreateFunction, typename DeleteFunction, typename ProbeFunction>
bool staysStale(shell::Shell& shell, const char* kind, CreateFunction create, DeleteFunction destroy,
                ProbeFunction probe)
{
    const Result<ObjectId> first = create();
    if (!check(shell, first.ok(), "the first object is created")) {
        return false;
    }
    bool ok = checkStatus(shell, destroy(first.value()), Status::Ok, "the first object is deleted");
    for (unsigned cycle = 1; ok && cycle <= kCycles; ++cycle) {
        const Result<ObjectId> next = create();
        if (!next.ok()) {
            shell.print("%s: Create failed at cycle %u: %s\r\n", kind, cycle, dcos::statusName(next.status()));
            return false;
        }
        if (next.value() == first.value() || probe(first.value()) != Status::StaleId) {
            shell.print("%s: the deleted id 0x%08lx answers again after %u cycles\r\n", kind,
                        static_cast<unsigned long>(first.value().raw()), cycle);
            ok = false;
        }
        ok &= checkStatus(shell, destroy(next.value()), Status::Ok, "Delete");
    }
    shell.print("%s: id 0x%08lx stale through %u create/delete cycles\r\n", kind,
                static_cast<unsigned long>(first.value().raw()), kCycles);
    return ok;
}

bool semaphoreIds(shell::Shell& shell)
{
    return staysStale(
        shell, "semaphore", [] { return dcos::semaphoreAgent.Create(dcos::SemaphoreAttributes{}); },
        [](ObjectId id) { return dcos::semaphoreAgent.Delete(id); },
        [](ObjectId id) { return dcos::semaphoreAgent.Release(id); });
}

bool portIds(shell::Shell& shell)
{
    return staysStale(
        shell, "port", [] { return dcos::messagePortAgent.Create(nullptr, dcos::Visibility::Local); },
        [](ObjectId id) { return dcos::messagePortAgent.Delete(id); },
        [](ObjectId id) { return dcos::messagePortAgent.Delete(id); });
}

bool timerIds(shell::Shell& shell)
{
    return staysStale(
        shell, "timer", [] { return dcos::timerAgent.Create(nullptr, dcos::Visibility::Local); },
        [](ObjectId id) { return dcos::timerAgent.Delete(id); },
        [](ObjectId id) { return dcos::timerAgent.CancelAlarm(id); });
}

void endAtOnce(uintptr_t) {}

bool taskIds(shell::Shell& shell)
{
    return staysStale(
        shell, "task",
        [] {
            dcos::TaskAttributes attributes;
            attributes.priority = 30; // Less urgent than the test: it never runs before it is killed.
            attributes.stackSize = dcos::kMinimumStackSize;
            return dcos::taskAgent.Create(attributes, endAtOnce, 0);
        },
        [](ObjectId id) { return dcos::taskAgent.KillTask(id); },
        [](ObjectId id) { return dcos::taskAgent.GetState(id).status(); });
}

} // namespace

DCOS_TARGET_TEST(staleSemaphoreIdTest, "stalesem", "a deleted semaphore's id stays stale for 3,000 cycles",
                 semaphoreIds);
DCOS_TARGET_TEST(stalePortIdTest, "staleport", "a deleted port's id stays stale for 3,000 cycles", portIds);
DCOS_TARGET_TEST(staleTimerIdTest, "staletimer", "a deleted timer's id stays stale for 3,000 cycles", timerIds);
DCOS_TARGET_TEST(staleTaskIdTest, "staletask", "a killed task's id stays stale for 3,000 cycles", taskIds);
