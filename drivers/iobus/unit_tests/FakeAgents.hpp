// Host-test stand-ins for the agent services MfioBoard and MfioClient use
// that the host build does not contain: InstallISR and RemoveISR of the
// system agent, PostEvent, IdOfSelf and ReceiveEvent of the task agent, and
// the timer agent's Uptime. FakeAgents.cpp defines them for the host test
// binary only; the firmware links the kernel's own. The device half of the
// system agent (Create, Open, Read, ...) is the real DeviceManager.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/SystemAgent.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace iobus_fake {

/// One routine installed with InstallISR.
struct InstalledIsr {
    unsigned line;
    dcos::SystemAgent::InterruptServiceRoutine isr;
    void* context;
};

/// One PostEvent call.
struct PostedEvent {
    dcos::ObjectId task;
    uint32_t events;
};

/// Clears everything below and sets the clock to 0.
void reset();

/// The routines installed, by line (RemoveISR erases them).
std::vector<InstalledIsr>& installedIsrs();

/// The status the next InstallISR returns (Ok after reset).
void failNextInstall(dcos::Status status);

/// Every PostEvent since reset().
std::vector<PostedEvent>& postedEvents();

/// The value Uptime returns; tests advance it.
uint64_t& uptimeNs();

/// Nanoseconds Uptime advances after each call (0 after reset), so polling loops see time pass.
void setUptimeStep(uint64_t ns);

/// What ReceiveEvent does: called with the requested events and time-out,
/// returns the result. The default times out after advancing the clock by the time-out.
void onReceiveEvent(std::function<dcos::Result<uint32_t>(uint32_t events, uint64_t timeoutNs)> handler);

/// Calls the routine installed on @p line, as the interrupt would; false when there is none.
bool raise(unsigned line);

} // namespace iobus_fake
