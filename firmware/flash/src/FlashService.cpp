// The kernel's flash service (FlashService.hpp).
#include <flash/FlashService.hpp>

#include <flash/FlashSession.hpp>

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
constexpr size_t kStackBytes = 8192;

ObjectId serviceTask;
ObjectId cardSemaphore;
FlashServiceState state;
const CanFlashServer* liveServer = nullptr;

image::TrustedKey trustedKeys[boot::ConfigurationBlock::kMaximumKeys];
size_t trustedKeyCount = 0;

// The card's configuration: the keys it trusts. Read once, at the task's start.
const char* readConfiguration(boot::SectorStore& store)
{
    const boot::StoredConfiguration stored = boot::ConfigurationStore::read(store);
    if (!stored.readable) {
        return "the card cannot be read";
    }
    if (!stored.present) {
        return "the card holds no valid configuration";
    }
    for (size_t i = 0; i < stored.configuration.keyCount; ++i) {
        trustedKeys[trustedKeyCount++] = image::TrustedKey::fromPoint(stored.configuration.keys[i]);
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

// The frame a queued message was on the bus.
bool frameOf(const SystemMessage& message, can::CanFrame& frame)
{
    if (message.source > can::MessageIdentifier::kMaxNodeNumber ||
        message.destination > can::MessageIdentifier::kMaxNodeNumber) {
        return false; // Flashing frames are never broadcast.
    }
    const can::LinkResult<can::MessageIdentifier> identifier =
        can::MessageIdentifier::make(message.priority, static_cast<can::MessageType>(message.type),
                                     static_cast<uint8_t>(message.destination), static_cast<uint8_t>(message.source));
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

// Sends what the server asked for, with an echo that confirms it.
void transmit(uint8_t interface, const CanFlashServer::Output& output)
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
    message.type = SystemMessageType::Flashing;
    message.destination = identifier.value().destination();
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
    uint8_t interface = 0xFF;
    uint8_t ownNode = can::MessageIdentifier::kBroadcast;

    for (;;) {
        const uint64_t deadline = server.nextDeadlineNs();
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
            if (message.echo) {
                if (from == interface) {
                    transmit(interface, server.onTransmitConfirmed(at));
                }
                continue;
            }
            can::CanFrame frame;
            if (!frameOf(message, frame)) {
                continue;
            }
            if (from != interface) {
                // The first frame from this interface: the server answers as
                // its CAN node, and a new connection begins there.
                interface = from;
                ownNode = ownNodeOf(from);
                server.setOwnNode(ownNode);
                state.interface = from;
            }
            CanFlashServer::Output output;
            {
                // A request's card work holds the card (the boot command's confirmation waits).
                dcos::internal::CardHold hold;
                output = server.onFrame(frame, at);
            }
            transmit(interface, output);
        }
        transmit(interface, server.poll(dcos::TimerAgent::Uptime()));
        state.peer = server.peer();
        RestartTarget target{};
        if (server.restartDue(target)) {
            runtime::format(bsp::console(), "flash: restarting %s, as host %u asked\r\n",
                            target == RestartTarget::Boot ? "into the new image" : "into the stage loader's recovery",
                            unsigned(server.peer()));
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
