// Host-test definitions of the agent services listed in FakeAgents.hpp.
#include "FakeAgents.hpp"

#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/KernelContext.hpp>

namespace iobus_fake {

namespace {

std::vector<InstalledIsr> isrs;
std::vector<PostedEvent> events;
uint64_t clock = 0;
uint64_t step = 0;
dcos::Status nextInstall = dcos::Status::Ok;
std::function<dcos::Result<uint32_t>(uint32_t, uint64_t)> receiveHandler;

dcos::Result<uint32_t> timeOut(uint32_t, uint64_t timeoutNs)
{
    clock += timeoutNs;
    return dcos::Status::Timeout;
}

} // namespace

void reset()
{
    isrs.clear();
    events.clear();
    clock = 0;
    step = 0;
    nextInstall = dcos::Status::Ok;
    receiveHandler = timeOut;
}

std::vector<InstalledIsr>& installedIsrs() { return isrs; }

void failNextInstall(dcos::Status status) { nextInstall = status; }

std::vector<PostedEvent>& postedEvents() { return events; }

uint64_t& uptimeNs() { return clock; }

void setUptimeStep(uint64_t ns) { step = ns; }

void onReceiveEvent(std::function<dcos::Result<uint32_t>(uint32_t, uint64_t)> handler)
{
    receiveHandler = std::move(handler);
}

bool raise(unsigned line)
{
    for (const InstalledIsr& installed : isrs) {
        if (installed.line == line) {
            installed.isr(installed.context);
            return true;
        }
    }
    return false;
}

} // namespace iobus_fake

namespace dcos {

Status SystemAgent::InstallISR(unsigned line, InterruptServiceRoutine isr, void* context)
{
    if (iobus_fake::nextInstall != Status::Ok) {
        const Status status = iobus_fake::nextInstall;
        iobus_fake::nextInstall = Status::Ok;
        return status;
    }
    for (const auto& installed : iobus_fake::isrs) {
        if (installed.line == line) {
            return Status::Busy;
        }
    }
    iobus_fake::isrs.push_back({line, isr, context});
    return Status::Ok;
}

Status SystemAgent::RemoveISR(unsigned line)
{
    for (auto it = iobus_fake::isrs.begin(); it != iobus_fake::isrs.end(); ++it) {
        if (it->line == line) {
            iobus_fake::isrs.erase(it);
            return Status::Ok;
        }
    }
    return Status::InvalidArgument;
}

Status TaskAgent::PostEvent(ObjectId task, uint32_t posted)
{
    iobus_fake::events.push_back({task, posted});
    return Status::Ok;
}

ObjectId TaskAgent::IdOfSelf() { return internal::currentTaskId(); }

Result<uint32_t> TaskAgent::ReceiveEvent(uint32_t wanted, EventWait, uint64_t timeout)
{
    if (!iobus_fake::receiveHandler) {
        iobus_fake::receiveHandler = iobus_fake::timeOut;
    }
    return iobus_fake::receiveHandler(wanted, timeout);
}

uint64_t TimerAgent::Uptime()
{
    const uint64_t now = iobus_fake::clock;
    iobus_fake::clock += iobus_fake::step;
    return now;
}

} // namespace dcos
