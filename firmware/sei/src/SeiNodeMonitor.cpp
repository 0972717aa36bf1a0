#include <sei/SeiNodeMonitor.hpp>

#include <sei/LogRing.hpp>

#include <arch_x86/Cpu.hpp>
#include <bsp/Board.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/NetworkLink.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/RemoteAgent.hpp>
#include <runtime/Format.hpp>

namespace sei {

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

// The console's copy. Static, not on the task's stack: the console writes
// into it from every context while the task runs or waits. 2 KiB holds
// about a second of a console at 19200 baud, more than the stream's Log
// frames need between two of the task's wakes.
LogRing<2048> consoleRing;

// The console's tap (bsp::setConsoleTap): every character it writes, with
// interrupts off around the ring, since a handler's output may interrupt a
// task's in the middle of a put. A few instructions; it never waits.
class ConsoleRingTap final : public runtime::CharacterSink {
public:
    void put(char character) override
    {
        arch_x86::InterruptGuard guard;
        (void)consoleRing.put(static_cast<uint8_t>(character));
    }
};
ConsoleRingTap consoleRingTap;

} // namespace

void NodeMonitorLog::capture(bool on)
{
    if (!on) {
        bsp::setConsoleTap(nullptr);
    }
    {
        arch_x86::InterruptGuard guard;
        consoleRing.clear();
    }
    if (on) {
        bsp::setConsoleTap(&consoleRingTap);
    }
}

size_t NodeMonitorLog::peek(uint8_t* out, size_t max)
{
    arch_x86::InterruptGuard guard;
    return consoleRing.peek(out, max);
}

void NodeMonitorLog::consume(size_t count)
{
    arch_x86::InterruptGuard guard;
    consoleRing.consume(count);
}

uint32_t NodeMonitorLog::takeLost(uint32_t max)
{
    arch_x86::InterruptGuard guard;
    return consoleRing.takeLost(max);
}

bool NodeMonitorLog::pending()
{
    arch_x86::InterruptGuard guard;
    return consoleRing.pending();
}

uint8_t NodeMonitorPages::open(uint32_t publisher, uint32_t& subscription)
{
    // Only this node's: another node's publisher would be a remote
    // transaction on every renewal, and its page is that node's to stream.
    const ObjectId id = ObjectId::fromRaw(publisher);
    if (id.node() != dcos::internal::localNode()) {
        return static_cast<uint8_t>(Status::InvalidId);
    }
    if (id.type() != dcos::ObjectType::DsmPublisher) {
        return static_cast<uint8_t>(Status::WrongType);
    }
    const Result<ObjectId> opened = dcos::DsmAgent::Open(id);
    if (!opened.ok()) {
        return static_cast<uint8_t>(opened.status());
    }
    subscription = opened.value().raw();
    return static_cast<uint8_t>(Status::Ok);
}

void NodeMonitorPages::close(uint32_t subscription)
{
    // A subscription whose publisher was deleted closes the same way;
    // nothing else can refuse the owner.
    (void)dcos::DsmAgent::Close(ObjectId::fromRaw(subscription));
}

bool NodeMonitorPages::read(uint32_t subscription, uint8_t (&page)[kSeiPageSize])
{
    // The last seen id kNoDsmData with no wait: the current page at once,
    // or WouldBlock for a publisher never written.
    dcos::DsmPage current;
    const Result<uint32_t> read =
        dcos::DsmAgent::Read(ObjectId::fromRaw(subscription), dcos::kNoDsmData, current, dcos::kPoll);
    if (!read.ok()) {
        return false;
    }
    for (size_t i = 0; i < kSeiPageSize; ++i) {
        page[i] = current.bytes[i];
    }
    return true;
}

bool NodeMonitorSender::send(const MonitorTarget& target, const uint8_t* data, uint8_t length)
{
    // Without an echo: nothing confirms the stream's frames, and the
    // transmit path's queue refusing one is counted by the stream.
    dcos::SystemMessage message;
    message.priority = target.priority;
    message.type = dcos::SystemMessageType::Monitoring;
    message.destination = target.host;
    message.length = length;
    for (uint8_t i = 0; i < length && i < sizeof message.data; ++i) {
        message.data[i] = data[i];
    }
    message.echo = false;
    return dcos::internal::sendOnLink(target.interface, message);
}

} // namespace sei
