// The global time base's kernel side (GlobalTime.hpp, docs/protocols/time.md):
// the master's sync task, and what the receiver task does with each
// TimeSync message. The decisions are ClockServo's; this file reads the
// clock, applies corrections and talks to the links.
#include <dcos/GlobalTime.hpp>
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/ClockServo.hpp>
#include <dcos/internal/GlobalTimeService.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/RemoteAgent.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimerManager.hpp>
#include <dcos/internal/TimeSyncMessage.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos {

namespace internal {

namespace {

using Lock = arch_x86::InterruptGuard;

constexpr uint64_t kNanosecondsPerSecond = 1'000'000'000;
constexpr uint64_t kNanosecondsPerMs = 1'000'000;
// The sync task's event: the role changed.
constexpr uint32_t kRoleChanged = 1u << 0;
// The sync task only builds and queues frames.
constexpr size_t kSyncTaskStackBytes = 2048;
// Above every application task, so that a busy node still keeps the
// interval; below the receiver (0), whose work it waits for.
constexpr uint8_t kSyncTaskPriority = 1;

// Everything below is shared by the receiver task, the sync task and the
// callers of GlobalTime; each touch is under the lock and O(1).
ClockServo servo;
// The sequence number of the Sync last sent on each interface, whose echo
// is waiting to be answered with a FollowUp.
uint8_t sentSequence[kNetworkInterfaces];
bool echoAwaited[kNetworkInterfaces];
ObjectId syncTask;

SystemMessage timeSyncMessage(const uint8_t* data, uint8_t length, bool echo)
{
    SystemMessage message;
    message.priority = 0; // docs/protocols/can.md: the least delay in arbitration.
    message.type = SystemMessageType::TimeSync;
    message.destination = NetworkLink::kBroadcast;
    message.length = length;
    message.echo = echo;
    __builtin_memcpy(message.data, data, length);
    return message;
}

// One Sync on every attached link, all with one sequence number.
void sendSyncs(uint8_t rank, uint32_t intervalMs)
{
    uint8_t sequence;
    {
        Lock lock;
        sequence = servo.nextSequence();
    }
    const uint64_t seconds = TimerManager::timeOfDayNs() / kNanosecondsPerSecond;
    uint8_t frame[kTimeSyncBytes];
    encodeTimeSync(sequence, seconds, rank, intervalMs, frame);
    const SystemMessage message = timeSyncMessage(frame, kTimeSyncBytes, true);
    for (uint8_t interface = 0; interface < kNetworkInterfaces; ++interface) {
        {
            // Noted before it is sent: the echo may come before Send
            // returns. An interface with no link takes nothing, and the
            // note is taken back below.
            Lock lock;
            sentSequence[interface] = sequence;
            echoAwaited[interface] = true;
        }
        if (!sendOnLink(interface, message)) {
            Lock lock;
            echoAwaited[interface] = false;
        }
    }
}

void syncTaskEntry(uintptr_t)
{
    for (;;) {
        GlobalTimeStatus configured;
        {
            Lock lock;
            configured = servo.status(TimerAgent::Uptime());
        }
        if (configured.role != TimeRole::Master) {
            (void)TaskAgent::ReceiveEvent(kRoleChanged, EventWait::Any, kWaitForever);
            continue;
        }
        // One interval, or less when the role changes meanwhile.
        const Result<uint32_t> woken = TaskAgent::ReceiveEvent(
            kRoleChanged, EventWait::Any, uint64_t{configured.intervalMs} * kNanosecondsPerMs);
        if (woken.ok()) {
            continue; // Reconfigured: read the role again.
        }
        bool sending;
        {
            Lock lock;
            sending = servo.sending(TimerAgent::Uptime());
        }
        if (sending) {
            sendSyncs(configured.rank, configured.intervalMs);
        }
    }
}

// This node's Sync went at @p sentAt on @p interface: tell its time.
void answerEcho(uint8_t interface, uint8_t sequence, uint64_t sentAt)
{
    {
        Lock lock;
        if (!echoAwaited[interface] || sentSequence[interface] != sequence) {
            return;
        }
        echoAwaited[interface] = false;
    }
    uint8_t frame[kTimeSyncBytes];
    encodeTimeFollowUp(sequence, TimerManager::timeOfDayAtUptime(sentAt), frame);
    if (sendOnLink(interface, timeSyncMessage(frame, kTimeSyncBytes, false))) {
        Lock lock;
        servo.countFollowUpSent();
    }
}

} // namespace

void onTimeSyncMessage(uint8_t interface, const SystemMessage& message)
{
    if (interface >= kNetworkInterfaces) {
        return;
    }
    TimeSyncFrame frame;
    if (decodeTimeSync(message.data, message.length, frame) != TimeSyncError::None) {
        Lock lock;
        servo.countMalformed();
        return;
    }
    // A link that does not timestamp gives the time the message is handled:
    // later by the receiver's delay, which then adds to the bound.
    const uint64_t at = message.timeNs != 0 ? message.timeNs : TimerAgent::Uptime();
    if (frame.kind == TimeSyncKind::Probe) {
        TimeProbe probe;
        probe.interface = interface;
        probe.sequence = frame.sequence;
        probe.source = message.source;
        probe.timeOfDayNs = TimerManager::timeOfDayAtUptime(at);
        Lock lock;
        servo.onProbe(probe);
        return;
    }
    if (message.echo) {
        if (frame.kind == TimeSyncKind::Sync && message.timeNs != 0) {
            answerEcho(interface, frame.sequence, message.timeNs);
        }
        return;
    }
    // Masters are told apart by logical node: a master on two buses is one.
    const Result<uint16_t> node = NetworkInterfacesManager::NodeAt(interface, message.source);
    if (!node.ok()) {
        Lock lock;
        servo.countMalformed();
        return;
    }
    if (frame.kind == TimeSyncKind::Sync) {
        Lock lock;
        servo.onSync(interface, node.value(), frame, at);
        return;
    }
    ClockCorrection correction;
    {
        Lock lock;
        correction = servo.onFollowUp(interface, node.value(), frame, at,
                                           [](uint64_t uptime) { return TimerManager::timeOfDayAtUptime(uptime); });
    }
    if (correction.apply) {
        (void)TimerManager::setTimeOfDayAt(correction.timeOfDayNs, correction.atUptimeNs);
    }
}

} // namespace internal

Status GlobalTime::SetRole(TimeRole role, uint8_t rank, uint32_t intervalMs)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    if (role != TimeRole::Off && role != TimeRole::Follower && role != TimeRole::Master) {
        return Status::InvalidArgument;
    }
    if (role == TimeRole::Master &&
        (rank > internal::kLastTimeMasterRank || intervalMs < internal::kShortestTimeSyncIntervalMs ||
         intervalMs > internal::kLongestTimeSyncIntervalMs || intervalMs % internal::kTimeSyncIntervalUnitMs != 0)) {
        return Status::InvalidArgument;
    }
    if (role != TimeRole::Master) {
        rank = 0;
        intervalMs = kDefaultTimeSyncIntervalMs;
    }
    if (role == TimeRole::Master && internal::syncTask.isNull()) {
        TaskAttributes attributes;
        attributes.name = "net-clock";
        attributes.priority = internal::kSyncTaskPriority;
        attributes.stackSize = internal::kSyncTaskStackBytes;
        attributes.newProcess = true;
        const Result<ObjectId> created = internal::TaskManager::create(attributes, internal::syncTaskEntry, 0);
        if (!created.ok()) {
            return created.status();
        }
        internal::syncTask = created.value();
    }
    {
        internal::Lock lock;
        // The node ranks itself among masters by its own number, known
        // once the board has read its command line, long before any role.
        internal::servo.setOwnNode(internal::localNode());
        internal::servo.configure(role, rank, intervalMs);
    }
    if (!internal::syncTask.isNull()) {
        (void)TaskAgent::PostEvent(internal::syncTask, internal::kRoleChanged);
    }
    return Status::Ok;
}

GlobalTimeStatus GlobalTime::GetStatus()
{
    internal::Lock lock;
    return internal::servo.status(TimerAgent::Uptime());
}

size_t GlobalTime::GetProbes(TimeProbe* probes, size_t capacity)
{
    if (probes == nullptr) {
        return 0;
    }
    internal::Lock lock;
    return internal::servo.probes(probes, capacity);
}

Status GlobalTime::SendProbe(uint8_t sequence)
{
    if (internal::inInterruptContext()) {
        return Status::InInterrupt;
    }
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    uint8_t frame[internal::kTimeProbeBytes];
    internal::encodeTimeProbe(sequence, frame);
    // Echoed, so that this node notes its own probe at the moment it went.
    const SystemMessage message = internal::timeSyncMessage(frame, internal::kTimeProbeBytes, true);
    bool sent = false;
    for (uint8_t interface = 0; interface < internal::kNetworkInterfaces; ++interface) {
        sent = internal::sendOnLink(interface, message) || sent;
    }
    return sent ? Status::Ok : Status::Unreachable;
}

} // namespace dcos
