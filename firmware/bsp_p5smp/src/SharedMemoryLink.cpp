#include <bsp/P5smpBoard.hpp>
#include <bsp/SharedMemoryLink.hpp>

#include <arch_x86/Cpu.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

#include <string.h>

namespace bsp {

namespace {

// The low half of the Pentium's time-stamp counter (RDTSC, which the i486
// lacks: this file is built for the dual-Pentium board only).
uint32_t timeStamp()
{
    uint32_t low;
    uint32_t high;
    asm volatile("rdtsc" : "=a"(low), "=d"(high));
    return low;
}

} // namespace

void SharedMemoryArea::layOut()
{
    magic = 0;
    toNode3.reset();
    toNode2.reset();
    signalledAt[0] = 0;
    signalledAt[1] = 0;
    version = kVersion;
    magic = kMagic;
}

dcos::Status SharedMemoryLink::Start(dcos::ObjectId receiver, uint32_t receiveEvent, uint32_t ownPhysical)
{
    if (!otherNodeRunning() || !SharedMemoryArea::at().laidOut()) {
        return dcos::Status::NotFound;
    }
    if (ownPhysical != processorIndex()) {
        return dcos::Status::InvalidArgument;
    }
    receiver_ = receiver;
    receiveEvent_ = receiveEvent;
    ownPhysical_ = ownPhysical;
    const dcos::Status installed = dcos::systemAgent.InstallISR(interProcessorLine, onSignal, this);
    if (installed != dcos::Status::Ok) {
        return installed;
    }
    started_ = true;
    // Messages the other node sent before this one listened are waiting:
    // the receiver task looks at once.
    (void)dcos::taskAgent.PostEvent(receiver_, receiveEvent_);
    return dcos::Status::Ok;
}

void SharedMemoryLink::Stop()
{
    if (started_) {
        (void)dcos::systemAgent.RemoveISR(interProcessorLine);
        started_ = false;
    }
}

void SharedMemoryLink::onSignal(void* context)
{
    const uint32_t now = timeStamp();
    auto* link = static_cast<SharedMemoryLink*>(context);
    // From the other node's stamp of its last signal: when it signalled
    // again before this routine ran, the latency of that later one.
    const uint32_t latency = now - SharedMemoryArea::at().signalledAt[link->ownPhysical_ ^ 1u];
    SharedMemoryLinkStatistics& counts = link->statistics_;
    counts.latencyLast = latency;
    counts.latencyMin = counts.interrupts == 0 || latency < counts.latencyMin ? latency : counts.latencyMin;
    counts.latencyMax = latency > counts.latencyMax ? latency : counts.latencyMax;
    ++counts.interrupts;
    (void)dcos::taskAgent.PostEvent(link->receiver_, link->receiveEvent_);
}

dcos::Status SharedMemoryLink::Send(const dcos::SystemMessage& message)
{
    if (!started_) {
        return dcos::Status::Busy;
    }
    if (message.echo) {
        return dcos::Status::NotSupported; // The area has no moment a message left.
    }
    const uint32_t other = ownPhysical_ ^ 1u;
    if (message.destination != other && message.destination != kBroadcast) {
        return dcos::Status::InvalidArgument;
    }
    SharedMemoryMessage slot{};
    slot.priority = message.priority;
    slot.type = static_cast<uint8_t>(message.type);
    slot.length = message.length <= sizeof slot.data ? message.length : sizeof slot.data;
    slot.destination = message.destination;
    slot.source = message.source == kBroadcast ? kBroadcast : ownPhysical_;
    memcpy(slot.data, message.data, slot.length);
    SharedMemoryArea& area = SharedMemoryArea::at();
    SharedMemoryRing& ring = ownPhysical_ == 0 ? area.toNode3 : area.toNode2;
    // One writer per ring on this node: tasks and the remote agent may send
    // at once, so the push and the signal are one step.
    arch_x86::InterruptGuard guard;
    if (!ring.push(slot)) {
        ++statistics_.ringFull;
        return dcos::Status::Busy;
    }
    ++statistics_.sent;
    area.signalledAt[ownPhysical_] = timeStamp();
    if (!signalOtherNode()) {
        ++statistics_.notSignalled;
    }
    return dcos::Status::Ok;
}

dcos::Result<bool> SharedMemoryLink::Receive(dcos::SystemMessage& message)
{
    if (!started_) {
        return false;
    }
    SharedMemoryArea& area = SharedMemoryArea::at();
    SharedMemoryRing& ring = ownPhysical_ == 0 ? area.toNode2 : area.toNode3;
    SharedMemoryMessage slot{};
    const SharedMemoryRing::Pop popped = ring.pop(slot);
    if (popped == SharedMemoryRing::Pop::Empty) {
        return false;
    }
    if (popped == SharedMemoryRing::Pop::Corrupted) {
        ++statistics_.corrupted;
        return dcos::Status::Corrupted;
    }
    ++statistics_.received;
    message = dcos::SystemMessage{};
    message.priority = slot.priority;
    message.type = static_cast<dcos::SystemMessageType>(slot.type);
    message.destination = slot.destination;
    message.source = slot.source == kBroadcast ? kBroadcast : (ownPhysical_ ^ 1u);
    message.length = slot.length <= sizeof message.data ? slot.length : sizeof message.data;
    memcpy(message.data, slot.data, message.length);
    message.timeNs = dcos::timerAgent.Uptime();
    return true;
}

} // namespace bsp
