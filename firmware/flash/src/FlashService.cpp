// The kernel's flash service (FlashService.hpp).
#include <flash/FlashService.hpp>

#include <flash/FlashSession.hpp>

#include <sei/CanSeiServer.hpp>
#include <sei/SeiAuthenticator.hpp>
#include <sei/SeiMonitor.hpp>
#include <sei/SeiNodeBackend.hpp>
#include <sei/SeiNodeMonitor.hpp>
#include <sei/SeiServer.hpp>
#include <sei/SeiService.hpp>

#include <ata/AtaPioDisk.hpp>
#include <boot/AtaSectorStore.hpp>
#include <boot/BootControl.hpp>
#include <boot/BootInfo.hpp>
#include <boot/ConfigurationStore.hpp>
#include <bsp/Board.hpp>
#include <bsp/BoardReset.hpp>
#include <can/MessageIdentifier.hpp>
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/Version.hpp>
#include <dcos/internal/FlashServiceHooks.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/RemoteAgent.hpp>
#include <image/ImageVerifier.hpp>
#include <runtime/Format.hpp>

namespace flash {

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::SystemMessage;
using dcos::SystemMessageType;

// Frames waiting for the service's task. The receiver task is the only
// writer of head, the service's task the only writer of tail, and a slot is
// written before head moves past it: no lock is needed on one processor.
// 64 frames hold four of the node's ISO-TP blocks (kCanNodeBlockSize) with
// their echoes, so a task held up by control work for a while loses nothing.
constexpr uint32_t kQueueSlots = 64;
struct QueuedFrame {
    uint8_t interface;
    SystemMessage message;
};
QueuedFrame queue[kQueueSlots];
volatile uint32_t head = 0;
volatile uint32_t tail = 0;

constexpr uint32_t kFrameEvent = 1u << 0;
// The task keeps both protocols' servers and the monitoring stream on its
// stack (the servers' buffers are a whole message each way), and the image
// checks and card calls run below them.
constexpr size_t kStackBytes = 16384;
constexpr size_t kServersBytes = sizeof(CanFlashServer) + sizeof(FlashSession) + sizeof(sei::CanSeiServer) +
                                 sizeof(sei::SeiServer) + sizeof(sei::SeiAuthenticator) +
                                 sizeof(sei::SeiNodeBackend) + sizeof(ata::AtaPioDisk) + sizeof(boot::AtaSectorStore) +
                                 sizeof(sei::SeiMonitor) + sizeof(sei::NodeMonitorLog) + sizeof(sei::NodeMonitorPages) +
                                 sizeof(sei::NodeMonitorSender) + sizeof(sei::NodeMonitorControl);
static_assert(kServersBytes <= kStackBytes / 2, "the servers leave half the agent's stack to the calls they make");

ObjectId serviceTask;
ObjectId cardSemaphore;
FlashServiceState state;
const CanFlashServer* liveServer = nullptr;
const sei::CanSeiServer* liveSeiServer = nullptr;
const sei::SeiAuthenticator* liveAuthenticator = nullptr;
const sei::SeiServer* liveSeiProtocol = nullptr;

image::TrustedKey trustedKeys[boot::ConfigurationBlock::kMaximumKeys];
size_t trustedKeyCount = 0;
// The card's configuration as the task found it at its start: the keys it
// trusts, and the node's identity for the configuration protocol.
boot::ConfigurationBlock configuration;
bool configured = false;

// Reads the card's configuration once, at the task's start; says why
// images cannot be taken, or null.
const char* readConfiguration(boot::SectorStore& store)
{
    const boot::StoredConfiguration stored = boot::ConfigurationStore::read(store);
    if (!stored.readable) {
        return "the card cannot be read";
    }
    if (!stored.present) {
        return "the card holds no valid configuration";
    }
    configuration = stored.configuration;
    configured = true;
    for (size_t i = 0; i < configuration.keyCount; ++i) {
        trustedKeys[trustedKeyCount++] = image::TrustedKey::fromPoint(configuration.keys[i]);
    }
    return trustedKeyCount == 0 ? "the card's configuration trusts no key" : nullptr;
}

// The CAN node number an interface has: the flash protocol's frames to it carry it.
uint8_t ownNodeOf(uint8_t interface)
{
    const Result<dcos::NetworkInterface> entry = dcos::NetworkInterfacesManager::GetInterface(interface);
    return entry.ok() && entry.value().physical <= can::MessageIdentifier::kMaxNodeNumber
               ? static_cast<uint8_t>(entry.value().physical)
               : can::MessageIdentifier::kBroadcast;
}

// The frame a queued message was on the bus. Only the configuration
// protocol's scans and its selected node's connection use the broadcast
// address; a host never sends from it.
bool frameOf(const SystemMessage& message, can::CanFrame& frame)
{
    const bool toEveryNode = message.destination == dcos::NetworkLink::kBroadcast;
    if (message.source > can::MessageIdentifier::kMaxNodeNumber ||
        (toEveryNode && message.type != SystemMessageType::Configuration) ||
        (!toEveryNode && message.destination > can::MessageIdentifier::kMaxNodeNumber)) {
        return false;
    }
    const uint8_t destination =
        toEveryNode ? can::MessageIdentifier::kBroadcast : static_cast<uint8_t>(message.destination);
    const can::LinkResult<can::MessageIdentifier> identifier =
        can::MessageIdentifier::make(message.priority, static_cast<can::MessageType>(message.type), destination,
                                     static_cast<uint8_t>(message.source));
    if (!identifier.ok()) {
        return false;
    }
    const can::LinkResult<can::CanFrame> made =
        can::CanFrame::makeData(identifier.value().encode(), can::IdFormat::Extended, message.data, message.length);
    if (!made.ok()) {
        return false;
    }
    frame = made.value();
    return true;
}

// Sends what a server asked for, with an echo that confirms it: of its
// protocol's message type, and from the broadcast address when the server
// answers as the configuration protocol's selected node or to a scan.
void transmit(uint8_t interface, const can::IsoTpRequestServer::Output& output)
{
    if (!output.transmit) {
        return;
    }
    const can::LinkResult<can::MessageIdentifier> identifier = can::MessageIdentifier::fromFrame(output.frame);
    if (!identifier.ok()) {
        return;
    }
    SystemMessage message;
    message.priority = identifier.value().priority();
    message.type = static_cast<SystemMessageType>(identifier.value().type());
    message.destination = identifier.value().destination();
    if (identifier.value().source() == can::MessageIdentifier::kBroadcast) {
        message.source = dcos::NetworkLink::kBroadcast;
    }
    message.length = output.frame.length();
    for (uint8_t i = 0; i < message.length; ++i) {
        message.data[i] = output.frame.data()[i];
    }
    message.echo = true;
    if (!dcos::internal::sendOnLink(interface, message)) {
        // The ISO-TP sender's N_As runs out, and the host asks again.
        ++state.sendFailures;
    }
}

// Bytes that differ from one start of the node to the next, for the
// challenges: the calendar time (the real-time clock's, read at boot) and
// the uptime, both to the nanosecond. Not secret: a challenge only has to
// be new (docs/protocols/flash.md). No time-stamp counter: an i486 has none.
void challengeSeed(uint8_t (&seed)[16])
{
    const uint64_t uptime = dcos::TimerAgent::Uptime();
    const Result<dcos::DateTime> now = dcos::TimerAgent::GetSystemClock();
    const dcos::DateTime clock = now.ok() ? now.value() : dcos::DateTime{};
    for (int i = 0; i < 8; ++i) {
        seed[i] = static_cast<uint8_t>(uptime >> (8 * i));
    }
    seed[8] = static_cast<uint8_t>(clock.year);
    seed[9] = clock.month ^ static_cast<uint8_t>(clock.year >> 8);
    seed[10] = clock.day;
    seed[11] = clock.hour;
    seed[12] = clock.minute;
    seed[13] = clock.second;
    seed[14] = static_cast<uint8_t>(clock.nanosecond);
    seed[15] = static_cast<uint8_t>(clock.nanosecond >> 8);
}

void serviceEntry(uintptr_t)
{
    ata::AtaPioDisk disk = ata::AtaPioDisk::primary();
    boot::AtaSectorStore store(disk);
    const boot::RunningImage running = boot::RunningImage::fromCommandLine(dcos::bootInfo().commandLine);
    {
        dcos::internal::CardHold hold;
        state.problem = readConfiguration(store);
    }
    state.keys = static_cast<uint8_t>(trustedKeyCount);
    state.fromCard = running.fromCard;
    state.runningSlot = running.fromCard && running.trial ? running.slot : boot::BootState::kNoSlot;

    SessionIdentity identity;
    identity.node = dcos::internal::localNode();
    identity.board = image::BoardType::Isa486;
    identity.mode = NodeMode::Application;
    identity.memoryEnd = (1u << 20) + dcos::bootInfo().upperMemoryKib * 1024u;
    // Only a trial must not be written over: a confirmed image's slot is
    // never the one Begin chooses.
    identity.runningSlot = state.runningSlot;
    uint8_t seed[16];
    challengeSeed(seed);
    FlashSession session(store, trustedKeys, trustedKeyCount, identity, seed, sizeof seed);
    CanFlashServer server(session, can::MessageIdentifier::kBroadcast);
    liveServer = &server;

    // The configuration protocol (docs/protocols/config.md), with the key,
    // serial number and lockout the card's configuration holds. Its
    // challenges are drawn from the same start-unique seed, told apart by a
    // byte so that they never repeat the flash protocol's, and from the
    // configuration's sequence and serial number: a node's first challenge
    // differs from any it drew before a store, and from another node's.
    uint8_t seiSeed[sizeof seed + 8];
    for (size_t i = 0; i < sizeof seed; ++i) {
        seiSeed[i] = seed[i];
    }
    seiSeed[0] ^= 0x5E;
    for (size_t i = 0; i < 4; ++i) {
        seiSeed[sizeof seed + i] = static_cast<uint8_t>(configuration.sequence >> (8 * i));
        seiSeed[sizeof seed + 4 + i] = static_cast<uint8_t>(configuration.serialNumber >> (8 * i));
    }
    sei::SeiNodeBackend backend(store, configuration.serialNumber,
                                running.fromCard && running.version[0] != '\0' ? running.version
                                                                                : dcos::versionString);
    sei::SeiAuthenticator authenticator(configured && configuration.hasConfigurationKey()
                                            ? configuration.configurationKey
                                            : nullptr,
                                        identity.node, configuration.serialNumber, configuration.lockoutSeconds,
                                        seiSeed, sizeof seiSeed);
    sei::SeiServer seiServer(backend, authenticator);
    sei::CanSeiServer seiCan(seiServer, can::MessageIdentifier::kBroadcast);
    liveSeiServer = &seiCan;
    liveAuthenticator = &authenticator;
    liveSeiProtocol = &seiServer;

    sei::NodeMonitorLog monitorLog;
    sei::NodeMonitorPages monitorPages;
    sei::NodeMonitorSender monitorSender;
    sei::SeiMonitor monitor(monitorPages, monitorLog, monitorSender);
    sei::NodeMonitorControl monitorControl(monitor);
    backend.setMonitor(&monitorControl);

    uint8_t interface = 0xFF;
    uint8_t ownNode = can::MessageIdentifier::kBroadcast;

    for (;;) {
        // The earliest of: the flash and configuration transfers' time-outs,
        // the backend's pending bit-rate switch, and the monitoring stream's
        // next sample, console frames or lease end.
        const uint64_t deadlines[] = {server.nextDeadlineNs(), seiCan.nextDeadlineNs(), backend.nextDeadlineNs(),
                                      monitor.nextDeadlineNs()};
        uint64_t deadline = deadlines[0];
        for (const uint64_t other : deadlines) {
            deadline = other < deadline ? other : deadline;
        }
        const uint64_t now = dcos::TimerAgent::Uptime();
        const uint64_t wait = deadline == can::IsoTpSender::kNoDeadline ? dcos::kWaitForever
                              : deadline > now                         ? deadline - now
                                                                       : 0;
        if (wait != 0) {
            (void)dcos::TaskAgent::ReceiveEvent(kFrameEvent, dcos::EventWait::Any, wait);
        }
        while (tail != head) {
            const QueuedFrame& queued = queue[tail % kQueueSlots];
            const uint8_t from = queued.interface;
            const SystemMessage message = queued.message;
            tail = tail + 1;
            const uint64_t at = dcos::TimerAgent::Uptime();
            const bool configurationFrame = message.type == SystemMessageType::Configuration;
            if (message.echo) {
                if (from == interface) {
                    transmit(interface, configurationFrame ? seiCan.onTransmitConfirmed(at)
                                                           : server.onTransmitConfirmed(at));
                }
                continue;
            }
            can::CanFrame frame;
            if (!frameOf(message, frame)) {
                continue;
            }
            if (from != interface) {
                // The first frame from this interface: the servers answer as
                // its CAN node, and a new connection begins there.
                interface = from;
                ownNode = ownNodeOf(from);
                server.setOwnNode(ownNode);
                seiCan.setOwnNode(ownNode);
                backend.setCanNode(ownNode);
                state.interface = from;
            }
            if (configurationFrame) {
                // A Monitor request that completes on this frame streams to
                // its sender, at its priority, on this interface.
                sei::MonitorTarget from;
                from.interface = interface;
                from.host = static_cast<uint8_t>(message.source);
                from.priority = message.priority;
                monitorControl.setRequestSource(from);
            }
            can::IsoTpRequestServer::Output output;
            {
                // A request's card work holds the card (the boot command's confirmation waits).
                dcos::internal::CardHold hold;
                output = configurationFrame ? seiCan.onFrame(frame, at) : server.onFrame(frame, at);
            }
            transmit(interface, output);
        }
        const uint64_t later = dcos::TimerAgent::Uptime();
        transmit(interface, server.poll(later));
        transmit(interface, seiCan.poll(later));
        backend.poll(later);
        monitor.poll(later);
        state.peer = server.peer();
        RestartTarget target{};
        if (server.restartDue(target)) {
            runtime::format(bsp::console(), "flash: restarting %s, as host %u asked\r\n",
                            target == RestartTarget::Boot ? "into the new image" : "into the stage loader's recovery",
                            unsigned(server.peer()));
            bsp::resetBoard();
        }
        if (seiCan.restartDue()) {
            runtime::format(bsp::console(), "sei: restarting, as a configuration host asked\r\n");
            bsp::resetBoard();
        }
    }
}

} // namespace

FlashServiceState flashServiceState()
{
    FlashServiceState copy = state;
    copy.running = !serviceTask.isNull();
    if (liveServer != nullptr) {
        copy.can = liveServer->statistics();
    }
    return copy;
}

} // namespace flash

namespace sei {

SeiServiceState seiServiceState()
{
    SeiServiceState copy;
    if (flash::liveSeiServer == nullptr || flash::liveAuthenticator == nullptr || flash::liveSeiProtocol == nullptr) {
        return copy;
    }
    const uint64_t now = dcos::TimerAgent::Uptime();
    copy.running = true;
    copy.hasKey = flash::liveAuthenticator->hasKey();
    copy.queriesClosed = flash::configuration.queriesClosed();
    copy.serial = flash::configuration.serialNumber;
    copy.lockoutSecondsLeft = flash::liveAuthenticator->lockoutSecondsLeft(now);
    copy.badMacs = flash::liveAuthenticator->badMacs();
    copy.selected = flash::liveSeiProtocol->selected();
    copy.can = flash::liveSeiServer->statistics();
    return copy;
}

} // namespace sei

namespace dcos::internal {

void flashServiceStart()
{
    if (!flash::serviceTask.isNull()) {
        return;
    }
    SemaphoreAttributes lock;
    lock.name = "card";
    lock.priorityInheritance = true;
    const Result<ObjectId> semaphore = SemaphoreAgent::Create(lock);
    if (semaphore.ok()) {
        flash::cardSemaphore = semaphore.value();
    }
    TaskAttributes attributes;
    attributes.name = "flash";
    attributes.priority = kLowestPriority;
    attributes.stackSize = flash::kStackBytes;
    attributes.newProcess = true;
    attributes.superUser = true;
    const Result<ObjectId> task = TaskAgent::Create(attributes, flash::serviceEntry, 0);
    if (!task.ok()) {
        runtime::format(bsp::console(), "flash: the service cannot start: %s\r\n", statusName(task.status()));
        return;
    }
    flash::serviceTask = task.value();
}

void flashServiceFrame(uint8_t interface, const SystemMessage& message)
{
    if (flash::serviceTask.isNull()) {
        return;
    }
    if (flash::head - flash::tail >= flash::kQueueSlots) {
        ++flash::state.dropped;
        return;
    }
    flash::QueuedFrame& slot = flash::queue[flash::head % flash::kQueueSlots];
    slot.interface = interface;
    slot.message = message;
    flash::head = flash::head + 1;
    ++flash::state.queued;
    (void)TaskAgent::PostEvent(flash::serviceTask, flash::kFrameEvent);
}

Status cardAcquire()
{
    return flash::cardSemaphore.isNull() ? Status::Ok : SemaphoreAgent::Acquire(flash::cardSemaphore, kWaitForever);
}

void cardRelease()
{
    if (!flash::cardSemaphore.isNull()) {
        (void)SemaphoreAgent::Release(flash::cardSemaphore);
    }
}

} // namespace dcos::internal
