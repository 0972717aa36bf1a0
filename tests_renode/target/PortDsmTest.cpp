// The message port agent (seed 7.9) and the distributed shared memory agent,
// local part (seed 7.10), on the target: every primitive with its errors,
// port order, time-outs, receivers woken by tasks and interrupt handlers,
// readers racing a writer, and recovery of a dead task's ports, publishers
// and subscriptions.
#include "SpareLine.hpp"
#include "KernelTestSupport.hpp"

#include <dcos/DsmAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SchedulerAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/DsmManager.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/PortManager.hpp>

#include <arch_x86/Cpu.hpp>

namespace target_test {

namespace {

using dcos::dsmAgent;
using dcos::DsmPage;
using dcos::Message;
using dcos::messagePortAgent;
using dcos::ObjectId;
using dcos::ObjectType;
using dcos::PortOrder;
using dcos::Result;
using dcos::Status;
using dcos::systemAgent;
using dcos::taskAgent;
using dcos::Visibility;
using dcos::internal::DsmManager;
using dcos::internal::PortManager;

constexpr uint64_t kMillisecond = 1000000;

// --- Shared helpers ---------------------------------------------------------

Message messageOf(uint32_t value)
{
    Message message{};
    for (size_t i = 0; i < dcos::kMessageSize; ++i) {
        message.bytes[i] = static_cast<uint8_t>(value >> (8 * (i % 4)));
    }
    return message;
}

uint32_t valueOf(const Message& message)
{
    return static_cast<uint32_t>(message.bytes[0]) | (static_cast<uint32_t>(message.bytes[1]) << 8) |
           (static_cast<uint32_t>(message.bytes[2]) << 16) | (static_cast<uint32_t>(message.bytes[3]) << 24);
}

// A page whose four 32-bit words all hold value.
DsmPage pageOf(uint32_t value)
{
    DsmPage page{};
    for (size_t i = 0; i < dcos::kDsmPageSize; ++i) {
        page.bytes[i] = static_cast<uint8_t>(value >> (8 * (i % 4)));
    }
    return page;
}

uint32_t wordOf(const DsmPage& page, size_t word)
{
    const uint8_t* b = page.bytes + 4 * word;
    return static_cast<uint32_t>(b[0]) | (static_cast<uint32_t>(b[1]) << 8) | (static_cast<uint32_t>(b[2]) << 16) |
           (static_cast<uint32_t>(b[3]) << 24);
}

// Whether all four words of a page are the same value: a torn page is not.
bool isUniform(const DsmPage& page)
{
    const uint32_t first = wordOf(page, 0);
    return wordOf(page, 1) == first && wordOf(page, 2) == first && wordOf(page, 3) == first;
}

size_t freeBuffers() { return PortManager::bufferCounts().free; }

// Runs job in a task of its own that is no super user (priority 10, more
// urgent than the test task) and waits until it has finished.
using Job = void (*)();

void jobEntry(uintptr_t job)
{
    reinterpret_cast<Job>(job)();
    finished();
}

bool runInOtherTask(shell::Shell& shell, Job job)
{
    const ObjectId task = spawn("other", 10, jobEntry, reinterpret_cast<uintptr_t>(job));
    return check(shell, !task.isNull(), "create a task that is not the owner") && waitForDone(shell, 1);
}

// Checks that call(id) refuses the null id, an unused slot, an index beyond
// the table, the live object's index under another type, another node's
// object (with @p remote: Remote with no network up, unless the call can
// say at once, as Receive does) and a deleted object's id.
template <typename Call>
bool rejectsBadIds(shell::Shell& shell, const char* what, ObjectType type, ObjectType otherType, ObjectId live,
                   ObjectId stale, Call call, Status remote = Status::Remote)
{
    const uint16_t node = dcos::internal::localNode();
    shell.print("%s: ", what);
    bool ok = checkStatus(shell, call(ObjectId::null()), Status::InvalidId, "the null id");
    ok = checkStatus(shell, call(ObjectId(node, type, 0x07F)), Status::InvalidId, "an unused slot") && ok;
    ok = checkStatus(shell, call(ObjectId(node, type, 0xFFF)), Status::InvalidId, "an index beyond the table") && ok;
    ok = checkStatus(shell, call(ObjectId(node, otherType, live.index())), Status::WrongType, "another type") && ok;
    // A node no table maps: node + 1 is the dual-Pentium board's node 3, which answers.
    ok = checkStatus(shell, call(ObjectId(static_cast<uint16_t>(node + 100), type, live.index())), remote,
                     "another node's object") && ok;
    ok = checkStatus(shell, call(stale), Status::StaleId, "a deleted object") && ok;
    shell.print("%s\r\n", ok ? "rejected" : "NOT ALL REJECTED");
    return ok;
}

// --- Message ports: every primitive and its errors -------------------------------

ObjectId sharedPort;

struct OtherTaskResults {
    Status send;
    Status receive;
    Status remove;
    Status xfer;
    Status addMsgBufs;
    Status addObjects;
};
OtherTaskResults otherResults;

void useAnotherTasksPort()
{
    Message message{};
    otherResults.send = messagePortAgent.Send(sharedPort, messageOf(7), 0);
    otherResults.receive = messagePortAgent.Receive(sharedPort, message, dcos::kPoll);
    otherResults.remove = messagePortAgent.Delete(sharedPort);
    otherResults.xfer = messagePortAgent.XferOwnership(sharedPort, taskAgent.IdOfSelf());
    otherResults.addMsgBufs = messagePortAgent.AddMsgBufs(8);
    otherResults.addObjects = messagePortAgent.AddObjects(8);
}

volatile uint32_t newOwnerReceived = 0;
volatile Status newOwnerReceive = Status::Ok;
volatile Status newOwnerGiveBack = Status::Ok;

void newOwnerEntry(uintptr_t)
{
    (void)taskAgent.ReceiveEvent(1, dcos::EventWait::Any, dcos::kWaitForever);
    Message message{};
    newOwnerReceive = messagePortAgent.Receive(sharedPort, message, dcos::kPoll);
    newOwnerReceived = valueOf(message);
    newOwnerGiveBack = messagePortAgent.XferOwnership(sharedPort, testTask());
    finished();
}

struct PortIsrResults {
    Status receivePoll;
    Status receiveWait;
    Status send;
    Status create;
};
PortIsrResults portIsr;

void portIsrRoutine(void*)
{
    Message message{};
    portIsr.receivePoll = messagePortAgent.Receive(sharedPort, message, dcos::kPoll);
    portIsr.receiveWait = messagePortAgent.Receive(sharedPort, message, kMillisecond);
    portIsr.send = messagePortAgent.Send(sharedPort, messageOf(0x15A), 4);
    portIsr.create = messagePortAgent.Create("from-isr", Visibility::Local).status();
}

bool portPrimitives(shell::Shell& shell)
{
    const uint16_t node = dcos::internal::localNode();
    Message message{};
    bool ok = checkStatus(shell, messagePortAgent.Create("a-name-too-long-for-a-port", Visibility::Local).status(),
                          Status::InvalidArgument, "Create with a name of 26 characters");
    ok = checkStatus(shell, messagePortAgent.Create("odd", Visibility::Local, static_cast<PortOrder>(7)).status(),
                     Status::InvalidArgument, "Create with an unknown order") && ok;
    const Result<ObjectId> created = messagePortAgent.Create("prims-port", Visibility::Local);
    ok = checkStatus(shell, created.status(), Status::Ok, "Create") && ok;
    const ObjectId port = created.value();
    sharedPort = port;
    ok = check(shell, port.type() == ObjectType::MessagePort && port.node() == node, "a port id of this node") && ok;
    const Result<ObjectId> found = messagePortAgent.NameToObject("prims-port");
    ok = check(shell, found.ok() && found.value() == port, "NameToObject finds the port") && ok;
    ok = checkStatus(shell, messagePortAgent.NameToObject("no-such-port").status(), Status::NotFound,
                     "NameToObject of an unknown name") && ok;

    // Send and Receive.
    ok = checkStatus(shell, messagePortAgent.Send(port, messageOf(1), 3), Status::Ok, "Send") && ok;
    ok = checkStatus(shell, messagePortAgent.Receive(port, message, dcos::kPoll), Status::Ok, "Receive") && ok;
    ok = check(shell, valueOf(message) == 1, "the message sent is the message received") && ok;
    ok = checkStatus(shell, messagePortAgent.Receive(port, message, dcos::kPoll), Status::WouldBlock,
                     "Receive polls an empty port") && ok;
    ok = checkStatus(shell, messagePortAgent.Send(port, messageOf(2), 32), Status::InvalidArgument,
                     "priority 32") && ok;
    ok = checkStatus(shell, messagePortAgent.Send(port, messageOf(2), -33), Status::InvalidArgument,
                     "priority -33") && ok;
    ok = checkStatus(shell, messagePortAgent.Receive(port, message, dcos::kPoll), Status::WouldBlock,
                     "a refused Send queued nothing") && ok;

    // Another task may send, but not receive, delete or give the port away,
    // and it is no super user, so it may not configure either.
    ok = runInOtherTask(shell, useAnotherTasksPort) && ok;
    ok = checkStatus(shell, otherResults.send, Status::Ok, "Send by another task") && ok;
    ok = checkStatus(shell, otherResults.receive, Status::NotOwner, "Receive by another task") && ok;
    ok = checkStatus(shell, otherResults.remove, Status::NotOwner, "Delete by another task") && ok;
    ok = checkStatus(shell, otherResults.xfer, Status::NotOwner, "XferOwnership by another task") && ok;
    ok = checkStatus(shell, otherResults.addMsgBufs, Status::NotPermitted, "AddMsgBufs by a user task") && ok;
    ok = checkStatus(shell, otherResults.addObjects, Status::NotPermitted, "AddObjects by a user task") && ok;
    ok = checkStatus(shell, messagePortAgent.Receive(port, message, dcos::kPoll), Status::Ok,
                     "the other task's message arrived") && ok;
    ok = check(shell, valueOf(message) == 7, "the other task's message is intact") && ok;

    // XferOwnership: the new owner receives, the old one no longer does.
    const ObjectId newOwner = spawn("new-owner", 10, newOwnerEntry);
    ok = check(shell, !newOwner.isNull(), "create the new owner") && ok;
    ok = checkStatus(shell, messagePortAgent.Send(port, messageOf(9), 0), Status::Ok, "Send before the transfer") && ok;
    ok = checkStatus(shell, messagePortAgent.XferOwnership(port, ObjectId(node, ObjectType::Task, 0x0FF)),
                     Status::InvalidId, "XferOwnership to no task") && ok;
    ok = checkStatus(shell, messagePortAgent.XferOwnership(port, ObjectId(static_cast<uint16_t>(node + 1),
                                                                          ObjectType::Task, newOwner.index())),
                     Status::Remote, "XferOwnership to another node's task") && ok;
    ok = checkStatus(shell, messagePortAgent.XferOwnership(port, newOwner), Status::Ok, "XferOwnership") && ok;
    ok = checkStatus(shell, messagePortAgent.Receive(port, message, dcos::kPoll), Status::NotOwner,
                     "the old owner no longer receives") && ok;
    (void)taskAgent.PostEvent(newOwner, 1);
    ok = waitForDone(shell, 1) && ok;
    ok = checkStatus(shell, newOwnerReceive, Status::Ok, "the new owner receives") && ok;
    ok = check(shell, newOwnerReceived == 9, "the new owner got the queued message") && ok;
    ok = checkStatus(shell, newOwnerGiveBack, Status::Ok, "the new owner gives the port back") && ok;

    // Interrupt handlers may send and poll, but not wait or create.
    ok = checkStatus(shell, systemAgent.InstallISR(target_test::spareLine(), portIsrRoutine, nullptr), Status::Ok,
                     "InstallISR") && ok;
    target_test::raiseSpareLine();
    ok = checkStatus(shell, systemAgent.RemoveISR(target_test::spareLine()), Status::Ok, "RemoveISR") && ok;
    ok = checkStatus(shell, portIsr.receivePoll, Status::WouldBlock, "Receive polls in an ISR") && ok;
    ok = checkStatus(shell, portIsr.receiveWait, Status::InInterrupt, "Receive may not wait in an ISR") && ok;
    ok = checkStatus(shell, portIsr.send, Status::Ok, "Send in an ISR") && ok;
    ok = checkStatus(shell, portIsr.create, Status::InInterrupt, "Create in an ISR") && ok;
    ok = checkStatus(shell, messagePortAgent.Receive(port, message, dcos::kPoll), Status::Ok,
                     "the ISR's message arrived") && ok;
    ok = check(shell, valueOf(message) == 0x15A, "the ISR's message is intact") && ok;

    // Forged, foreign, mistyped and stale ids, for every primitive taking one.
    const ObjectId stale = messagePortAgent.Create("short-lived", Visibility::Local).value();
    ok = checkStatus(shell, messagePortAgent.Delete(stale), Status::Ok, "Delete") && ok;
    ok = checkStatus(shell, messagePortAgent.Delete(stale), Status::StaleId, "Delete twice") && ok;
    ok = rejectsBadIds(shell, "Send", ObjectType::MessagePort, ObjectType::Timer, port, stale,
                       [](ObjectId id) { return messagePortAgent.Send(id, messageOf(0), 0); }) && ok;
    // Only a port's owner receives, and another node's port has its owner there.
    ok = rejectsBadIds(
             shell, "Receive", ObjectType::MessagePort, ObjectType::Semaphore, port, stale,
             [](ObjectId id) {
                 Message m{};
                 return messagePortAgent.Receive(id, m, dcos::kPoll);
             },
             Status::NotOwner) &&
         ok;
    ok = rejectsBadIds(shell, "Delete", ObjectType::MessagePort, ObjectType::DsmPublisher, port, stale,
                       [](ObjectId id) { return messagePortAgent.Delete(id); }) && ok;
    ok = rejectsBadIds(shell, "XferOwnership", ObjectType::MessagePort, ObjectType::Task, port, stale,
                       [](ObjectId id) { return messagePortAgent.XferOwnership(id, testTask()); }) && ok;

    // A full table, and AddObjects.
    ObjectId ports[dcos::internal::kPortCapacity];
    size_t count = 0;
    Status last = Status::Ok;
    while (count < dcos::internal::kPortCapacity) {
        const Result<ObjectId> id = messagePortAgent.Create(nullptr, Visibility::Local, PortOrder::Fifo);
        if (!id.ok()) {
            last = id.status();
            break;
        }
        ports[count++] = id.value();
    }
    shell.print("created %u more ports, then: %s\r\n", static_cast<unsigned>(count), dcos::statusName(last));
    ok = checkStatus(shell, last, Status::TableFull, "a full port table") && ok;
    ok = checkStatus(shell, messagePortAgent.AddObjects(5), Status::InvalidArgument, "AddObjects(5)") && ok;
    ok = checkStatus(shell, messagePortAgent.AddObjects(dcos::internal::kPortCapacity), Status::TableFull,
                     "AddObjects beyond the capacity") && ok;
    ok = checkStatus(shell, messagePortAgent.AddObjects(8), Status::Ok, "AddObjects(8)") && ok;
    size_t more = 0;
    while (more < 8 && count < dcos::internal::kPortCapacity) {
        const Result<ObjectId> id = messagePortAgent.Create(nullptr, Visibility::Local);
        if (!id.ok()) {
            break;
        }
        ports[count++] = id.value();
        ++more;
    }
    ok = check(shell, more == 8, "AddObjects made room for eight more ports") && ok;
    for (size_t i = 0; i < count; ++i) {
        (void)messagePortAgent.Delete(ports[i]);
    }
    ok = checkStatus(shell, messagePortAgent.Delete(port), Status::Ok, "Delete the port") && ok;
    ok = checkStatus(shell, messagePortAgent.Send(port, messageOf(1), 0), Status::StaleId,
                     "Send to a deleted port") && ok;
    return ok;
}

DCOS_TARGET_TEST(portPrimitivesTest, "portprims", "message ports: every primitive with its errors", portPrimitives);

// --- Message buffers: exhaustion, AddMsgBufs, direct hand-over -----------------------

volatile uint32_t handedOver = 0;
volatile Status handOverStatus = Status::Ok;
ObjectId handOverPort;

void waitingReceiverEntry(uintptr_t)
{
    handOverPort = messagePortAgent.Create("hand-over", Visibility::Local).value();
    Message message{};
    handOverStatus = messagePortAgent.Receive(handOverPort, message, dcos::kWaitForever);
    handedOver = valueOf(message);
    (void)messagePortAgent.Delete(handOverPort);
    finished();
}

bool messageBuffers(shell::Shell& shell)
{
    const dcos::internal::MessageBufferCounts before = PortManager::bufferCounts();
    shell.print("message buffers: %u free of %u active, %u reserved\r\n", static_cast<unsigned>(before.free),
                static_cast<unsigned>(before.active), static_cast<unsigned>(before.reserved));
    const ObjectId port = messagePortAgent.Create("buffers", Visibility::Local).value();
    bool ok = check(shell, !port.isNull(), "create the port");

    // Send until the area is exhausted: the refused message is not queued.
    uint32_t sent = 0;
    Status refused = Status::Ok;
    while (sent <= before.free) {
        refused = messagePortAgent.Send(port, messageOf(sent), 7);
        if (refused != Status::Ok) {
            break;
        }
        ++sent;
    }
    shell.print("sent %lu messages, then: %s\r\n", static_cast<unsigned long>(sent), dcos::statusName(refused));
    ok = checkStatus(shell, refused, Status::NoMemory, "Send with no buffer left") && ok;
    ok = check(shell, sent == before.free && freeBuffers() == 0, "every free buffer was used") && ok;
    ok = checkStatus(shell, messagePortAgent.Send(port, messageOf(sent), 7), Status::NoMemory, "Send again") && ok;

    // A waiting receiver still gets a message: it needs no buffer.
    ok = check(shell, !spawn("hand-over", 10, waitingReceiverEntry).isNull(), "create a waiting receiver") && ok;
    ok = checkStatus(shell, messagePortAgent.Send(handOverPort, messageOf(0xABCD), 0), Status::Ok,
                     "Send to a waiting receiver with no buffer left") && ok;
    ok = waitForDone(shell, 1) && ok;
    ok = checkStatus(shell, handOverStatus, Status::Ok, "the receiver was woken") && ok;
    ok = check(shell, handedOver == 0xABCD, "the receiver got the message") && ok;

    // AddMsgBufs: its errors, then the sender's retry succeeds.
    ok = checkStatus(shell, messagePortAgent.AddMsgBufs(0), Status::InvalidArgument, "AddMsgBufs(0)") && ok;
    ok = checkStatus(shell, messagePortAgent.AddMsgBufs(before.reserved - before.active + 1), Status::NoMemory,
                     "AddMsgBufs beyond the reserve") && ok;
    ok = check(shell, PortManager::bufferCounts().active == before.active,
               "a refused AddMsgBufs activates nothing") && ok;
    ok = checkStatus(shell, messagePortAgent.AddMsgBufs(8), Status::Ok, "AddMsgBufs(8)") && ok;
    ok = check(shell, PortManager::bufferCounts().active == before.active + 8 && freeBuffers() == 8,
               "eight more buffers are free") && ok;
    ok = checkStatus(shell, messagePortAgent.Send(port, messageOf(sent), 7), Status::Ok, "the retried Send") && ok;

    // Nothing was lost or duplicated: every message arrives once, in order.
    uint32_t received = 0;
    bool inOrder = true;
    Message message{};
    while (messagePortAgent.Receive(port, message, dcos::kPoll) == Status::Ok) {
        inOrder = inOrder && valueOf(message) == received;
        ++received;
    }
    shell.print("received %lu messages\r\n", static_cast<unsigned long>(received));
    ok = check(shell, received == sent + 1 && inOrder, "every accepted message arrived once, in order") && ok;
    ok = check(shell, freeBuffers() == before.free + 8, "every buffer came back") && ok;

    // Deleting a port hands its queued buffers back.
    for (uint32_t i = 0; i < 20; ++i) {
        (void)messagePortAgent.Send(port, messageOf(i), static_cast<int>(i % 32) - 16);
    }
    ok = check(shell, freeBuffers() == before.free + 8 - 20, "twenty buffers hold messages") && ok;
    ok = checkStatus(shell, messagePortAgent.Delete(port), Status::Ok, "Delete with messages queued") && ok;
    ok = check(shell, freeBuffers() == before.free + 8, "Delete gave the queued buffers back") && ok;
    return ok;
}

DCOS_TARGET_TEST(messageBuffersTest, "portbufs", "no buffer left: Send refuses, nothing lost; AddMsgBufs",
                 messageBuffers);

// --- Message ports: FIFO, priority and LIFO order ----------------------------------------

struct Sent {
    char mark;
    int priority;
};

// Sends marks with their priorities, receives everything and compares.
bool checkOrder(shell::Shell& shell, PortOrder order, const Sent* sequence, size_t length, const char* expected)
{
    const ObjectId port = messagePortAgent.Create(nullptr, Visibility::Local, order).value();
    bool ok = check(shell, !port.isNull(), "create the port");
    for (size_t i = 0; i < length; ++i) {
        ok = checkStatus(shell, messagePortAgent.Send(port, messageOf(static_cast<uint8_t>(sequence[i].mark)),
                                                      sequence[i].priority),
                         Status::Ok, "Send") && ok;
    }
    char received[32] = {};
    size_t count = 0;
    Message message{};
    while (count + 1 < sizeof received && messagePortAgent.Receive(port, message, dcos::kPoll) == Status::Ok) {
        received[count++] = static_cast<char>(message.bytes[0]);
    }
    size_t i = 0;
    while (expected[i] != '\0' && received[i] == expected[i]) {
        ++i;
    }
    const bool same = expected[i] == '\0' && received[i] == '\0';
    shell.print("%s port: received \"%s\", expected \"%s\": %s\r\n", order == PortOrder::Fifo ? "FIFO" : "priority",
                received, expected, same ? "same" : "DIFFERENT");
    (void)messagePortAgent.Delete(port);
    return same && ok;
}

bool portOrder(shell::Shell& shell)
{
    // FIFO: the level is ignored, a negative priority goes to the head.
    const Sent fifo[] = {{'a', 5}, {'b', 0}, {'c', -3}, {'d', 31}, {'e', -1}, {'f', dcos::kLifoMostUrgent}, {'g', 9}};
    bool ok = checkOrder(shell, PortOrder::Fifo, fifo, sizeof fifo / sizeof fifo[0], "fecabdg");
    // Priority: most urgent level first, FIFO among equals, LIFO for
    // negative priorities at their level, kLifoMostUrgent at level 0.
    const Sent priority[] = {{'a', 10}, {'b', 3},  {'c', 10}, {'d', -10}, {'e', 0},  {'f', dcos::kLifoMostUrgent},
                             {'g', 31}, {'h', 3},  {'i', -3}, {'j', -31}, {'k', 31}, {'l', 0}};
    ok = checkOrder(shell, PortOrder::Priority, priority, sizeof priority / sizeof priority[0], "felibhdacjgk") && ok;
    // The default order is priority.
    const ObjectId port = messagePortAgent.Create(nullptr, Visibility::Local).value();
    (void)messagePortAgent.Send(port, messageOf('x'), 20);
    (void)messagePortAgent.Send(port, messageOf('y'), 2);
    Message message{};
    (void)messagePortAgent.Receive(port, message, dcos::kPoll);
    ok = check(shell, message.bytes[0] == 'y', "ports are priority ordered by default") && ok;
    (void)messagePortAgent.Delete(port);
    return ok;
}

DCOS_TARGET_TEST(portOrderTest, "portorder", "message ports: FIFO, priority and LIFO order", portOrder);

// --- Message ports: time-out, poll, Delete of a waited-on port ------------------------------

ObjectId deletedPort;
volatile Status deletedWaitStatus = Status::Ok;

void waitOnDoomedPortEntry(uintptr_t)
{
    deletedPort = messagePortAgent.Create("doomed", Visibility::Local).value();
    Message message{};
    deletedWaitStatus = messagePortAgent.Receive(deletedPort, message, dcos::kWaitForever);
    finished();
}

bool portTimeout(shell::Shell& shell)
{
    const ObjectId port = messagePortAgent.Create(nullptr, Visibility::Local).value();
    Message message{};
    bool ok = checkStatus(shell, messagePortAgent.Receive(port, message, dcos::kPoll), Status::WouldBlock, "poll");
    const uint64_t before = dcos::timerAgent.Uptime();
    ok = checkStatus(shell, messagePortAgent.Receive(port, message, 10 * kMillisecond), Status::Timeout,
                     "time-out") && ok;
    const uint64_t waited = dcos::timerAgent.Uptime() - before;
    shell.print("waited %llu ns for a 10 ms time-out\r\n", static_cast<unsigned long long>(waited));
    ok = check(shell, waited >= 10 * kMillisecond && waited <= 12 * kMillisecond, "a time-out of 10 ms") && ok;
    // A message sent after a time-out is not lost: it waits for the next Receive.
    (void)messagePortAgent.Send(port, messageOf(5), 1);
    ok = checkStatus(shell, messagePortAgent.Receive(port, message, 10 * kMillisecond), Status::Ok,
                     "Receive with a message queued returns at once") && ok;
    ok = check(shell, valueOf(message) == 5, "the queued message") && ok;
    (void)messagePortAgent.Delete(port);

    // Deleting a port wakes its waiting receiver with Deleted (a super user
    // may delete another task's port).
    ok = check(shell, !spawn("doomed", 10, waitOnDoomedPortEntry).isNull(), "create the receiver") && ok;
    dcos::internal::PortInfo info{};
    ok = check(shell, PortManager::snapshot(deletedPort.index() & (dcos::internal::kPortCapacity - 1), info) &&
                          info.receiverWaiting, "the receiver waits") && ok;
    ok = checkStatus(shell, messagePortAgent.Delete(deletedPort), Status::Ok, "Delete the waited-on port") && ok;
    ok = waitForDone(shell, 1) && ok;
    ok = checkStatus(shell, deletedWaitStatus, Status::Deleted, "the receiver was woken with Deleted") && ok;
    return ok;
}

DCOS_TARGET_TEST(portTimeoutTest, "porttimeout", "Receive: time-out, poll, woken by Delete", portTimeout);

// --- Message ports: a blocked receiver woken by a task and by an ISR -----------------------

ObjectId wakePort;
volatile uint32_t wokenWith[2] = {};

void wakeReceiverEntry(uintptr_t)
{
    wakePort = messagePortAgent.Create("wake", Visibility::Local).value();
    for (volatile uint32_t& value : wokenWith) {
        Message message{};
        const Status status = messagePortAgent.Receive(wakePort, message, dcos::kWaitForever);
        value = status == Status::Ok ? valueOf(message) : 0xDEAD;
        Trace::record('R');
    }
    (void)messagePortAgent.Delete(wakePort);
    finished();
}

void wakeSenderEntry(uintptr_t)
{
    Trace::record('t');
    (void)messagePortAgent.Send(wakePort, messageOf(0x7A5C), 5);
    Trace::record('T'); // After the more urgent receiver has run.
    finished();
}

void wakeIsr(void*)
{
    Trace::record('i');
    (void)messagePortAgent.Send(wakePort, messageOf(0x15F), 5);
    Trace::record('I');
}

bool portWake(shell::Shell& shell)
{
    Trace::clear();
    const size_t freeBefore = freeBuffers();
    const ObjectId receiver = spawn("receiver", 10, wakeReceiverEntry);
    bool ok = check(shell, !receiver.isNull(), "create the receiver");
    ok = check(shell, taskAgent.GetState(receiver).value() == dcos::TaskState::Blocked, "the receiver waits") && ok;
    // A task sends: the receiver (priority 10) preempts the sender (12) at once.
    ok = check(shell, !spawn("sender", 12, wakeSenderEntry).isNull(), "create the sender") && ok;
    ok = waitForDone(shell, 1) && ok;
    ok = check(shell, wokenWith[0] == 0x7A5C, "woken by a task with its message") && ok;
    // An ISR sends: the receiver runs at the outermost exit, before the test task goes on.
    ok = checkStatus(shell, systemAgent.InstallISR(target_test::spareLine(), wakeIsr, nullptr), Status::Ok, "InstallISR") && ok;
    Trace::record('s');
    target_test::raiseSpareLine();
    Trace::record('S');
    ok = checkStatus(shell, systemAgent.RemoveISR(target_test::spareLine()), Status::Ok, "RemoveISR") && ok;
    ok = waitForDone(shell, 1) && ok;
    ok = check(shell, wokenWith[1] == 0x15F, "woken by an ISR with its message") && ok;
    ok = check(shell, freeBuffers() == freeBefore, "a waiting receiver's messages took no buffer") && ok;
    return Trace::expect(shell, "tRTsiIRS") && ok;
}

DCOS_TARGET_TEST(portWakeTest, "portwake", "a blocked receiver is woken by Send from a task and from an ISR", portWake);

// --- Distributed shared memory: every primitive and its errors -----------------------------

ObjectId sharedPublisher;
ObjectId sharedSubscription;

struct DsmOtherResults {
    Status write;
    Status remove;
    Status open;
    Status readOwn;
    Status readOthers;
    Status closeOthers;
    Status xfer;
    Status addObjects;
    Status addSubscribers;
    uint32_t dataId;
};
DsmOtherResults dsmOther;

void useAnotherTasksPublisher()
{
    DsmPage page{};
    dsmOther.write = dsmAgent.Write(sharedPublisher, pageOf(66)).status();
    dsmOther.remove = dsmAgent.Delete(sharedPublisher);
    dsmOther.xfer = dsmAgent.XferOwnership(sharedPublisher, taskAgent.IdOfSelf());
    dsmOther.readOthers = dsmAgent.Read(sharedSubscription, dcos::kNoDsmData, page, dcos::kPoll).status();
    dsmOther.closeOthers = dsmAgent.Close(sharedSubscription);
    const Result<ObjectId> own = dsmAgent.Open(sharedPublisher);
    dsmOther.open = own.status();
    const Result<uint32_t> read = dsmAgent.Read(own.value(), dcos::kNoDsmData, page, dcos::kPoll);
    dsmOther.readOwn = read.status();
    dsmOther.dataId = read.ok() && wordOf(page, 0) == 55 ? read.value() : 0;
    (void)dsmAgent.Close(own.value());
    dsmOther.addObjects = dsmAgent.AddObjects(8);
    dsmOther.addSubscribers = dsmAgent.AddSubscribers(8);
}

volatile Status newWriterStatus = Status::Ok;
volatile Status newWriterGiveBack = Status::Ok;

void newWriterEntry(uintptr_t)
{
    (void)taskAgent.ReceiveEvent(1, dcos::EventWait::Any, dcos::kWaitForever);
    newWriterStatus = dsmAgent.Write(sharedPublisher, pageOf(77)).status();
    newWriterGiveBack = dsmAgent.XferOwnership(sharedPublisher, testTask());
    finished();
}

struct DsmIsrResults {
    Status write;
    Status readPoll;
    Status readWait;
    Status create;
    Status open;
    uint32_t readId;
};
DsmIsrResults dsmIsr;

void dsmIsrRoutine(void*)
{
    DsmPage page{};
    const Result<uint32_t> written = dsmAgent.Write(sharedPublisher, pageOf(88));
    dsmIsr.write = written.status();
    const Result<uint32_t> read = dsmAgent.Read(sharedSubscription, dcos::kNoDsmData, page, dcos::kPoll);
    dsmIsr.readPoll = read.status();
    dsmIsr.readId = read.ok() && isUniform(page) && wordOf(page, 0) == 88 ? read.value() : 0;
    dsmIsr.readWait = dsmAgent.Read(sharedSubscription, read.ok() ? read.value() : 0, page, kMillisecond).status();
    dsmIsr.create = dsmAgent.Create("from-isr", Visibility::Local).status();
    dsmIsr.open = dsmAgent.Open(sharedPublisher).status();
}

// Fills a table to TableFull with create(), checks that add(8) makes room
// for eight more and add(5) is refused, and deletes them all with remove().
template <typename Create, typename Add, typename Remove>
bool fillTable(shell::Shell& shell, const char* what, size_t capacity, Create create, Add add, Remove remove)
{
    static ObjectId objects[256];
    size_t count = 0;
    Status last = Status::Ok;
    while (count < capacity && count < 256) {
        const Result<ObjectId> id = create();
        if (!id.ok()) {
            last = id.status();
            break;
        }
        objects[count++] = id.value();
    }
    shell.print("%s: created %u more, then: %s\r\n", what, static_cast<unsigned>(count), dcos::statusName(last));
    bool ok = checkStatus(shell, last, Status::TableFull, "a full table");
    ok = checkStatus(shell, add(5), Status::InvalidArgument, "groups of eight") && ok;
    ok = checkStatus(shell, add(capacity), Status::TableFull, "beyond the capacity") && ok;
    ok = checkStatus(shell, add(8), Status::Ok, "eight more") && ok;
    size_t more = 0;
    while (more < 8 && count < 256) {
        const Result<ObjectId> id = create();
        if (!id.ok()) {
            break;
        }
        objects[count++] = id.value();
        ++more;
    }
    ok = check(shell, more == 8, "room for eight more") && ok;
    for (size_t i = 0; i < count; ++i) {
        remove(objects[i]);
    }
    return ok;
}

bool dsmPrimitives(shell::Shell& shell)
{
    const uint16_t node = dcos::internal::localNode();
    DsmPage page{};
    bool ok = checkStatus(shell, dsmAgent.Create("a-name-too-long-for-it", Visibility::Local).status(),
                          Status::InvalidArgument, "Create with a name of 22 characters");
    const Result<ObjectId> created = dsmAgent.Create("prims-pub", Visibility::Local);
    ok = checkStatus(shell, created.status(), Status::Ok, "Create") && ok;
    const ObjectId publisher = created.value();
    sharedPublisher = publisher;
    ok = check(shell, publisher.type() == ObjectType::DsmPublisher && publisher.node() == node,
               "a publisher id of this node") && ok;
    const Result<ObjectId> found = dsmAgent.NameToObject("prims-pub");
    ok = check(shell, found.ok() && found.value() == publisher, "NameToObject finds the publisher") && ok;
    ok = checkStatus(shell, dsmAgent.NameToObject("no-such-pub").status(), Status::NotFound, "an unknown name") && ok;

    // Open, Write, Read, Close.
    const Result<ObjectId> opened = dsmAgent.Open(publisher);
    ok = checkStatus(shell, opened.status(), Status::Ok, "Open") && ok;
    const ObjectId subscription = opened.value();
    sharedSubscription = subscription;
    ok = check(shell, subscription.type() == ObjectType::DsmSubscription, "a subscription id") && ok;
    ok = checkStatus(shell, dsmAgent.Read(subscription, dcos::kNoDsmData, page, dcos::kPoll).status(),
                     Status::WouldBlock, "Read before the first Write") && ok;
    const Result<uint32_t> first = dsmAgent.Write(publisher, pageOf(55));
    ok = check(shell, first.ok() && first.value() != dcos::kNoDsmData, "Write returns a data identifier") && ok;
    const Result<uint32_t> read = dsmAgent.Read(subscription, dcos::kNoDsmData, page, dcos::kPoll);
    ok = check(shell, read.ok() && read.value() == first.value() && isUniform(page) && wordOf(page, 0) == 55,
               "Read returns the page and its identifier") && ok;

    // Another task may subscribe and read through its own subscription, but
    // not write, delete, give away, or use the test task's subscription.
    ok = runInOtherTask(shell, useAnotherTasksPublisher) && ok;
    ok = checkStatus(shell, dsmOther.write, Status::NotOwner, "Write by another task") && ok;
    ok = checkStatus(shell, dsmOther.remove, Status::NotOwner, "Delete by another task") && ok;
    ok = checkStatus(shell, dsmOther.xfer, Status::NotOwner, "XferOwnership by another task") && ok;
    ok = checkStatus(shell, dsmOther.readOthers, Status::NotOwner, "Read through another task's subscription") && ok;
    ok = checkStatus(shell, dsmOther.closeOthers, Status::NotOwner, "Close of another task's subscription") && ok;
    ok = checkStatus(shell, dsmOther.open, Status::Ok, "Open by another task") && ok;
    ok = checkStatus(shell, dsmOther.readOwn, Status::Ok, "Read through its own subscription") && ok;
    ok = check(shell, dsmOther.dataId == first.value(), "the other task read the page") && ok;
    ok = checkStatus(shell, dsmOther.addObjects, Status::NotPermitted, "AddObjects by a user task") && ok;
    ok = checkStatus(shell, dsmOther.addSubscribers, Status::NotPermitted, "AddSubscribers by a user task") && ok;

    // XferOwnership: the new owner writes, the old one no longer does.
    const ObjectId newWriter = spawn("new-writer", 10, newWriterEntry);
    ok = checkStatus(shell, dsmAgent.XferOwnership(publisher, ObjectId(node, ObjectType::Task, 0x0FF)),
                     Status::InvalidId, "XferOwnership to no task") && ok;
    ok = checkStatus(shell, dsmAgent.XferOwnership(publisher, newWriter), Status::Ok, "XferOwnership") && ok;
    ok = checkStatus(shell, dsmAgent.Write(publisher, pageOf(1)).status(), Status::NotOwner,
                     "the old owner no longer writes") && ok;
    (void)taskAgent.PostEvent(newWriter, 1);
    ok = waitForDone(shell, 1) && ok;
    ok = checkStatus(shell, newWriterStatus, Status::Ok, "the new owner writes") && ok;
    ok = checkStatus(shell, newWriterGiveBack, Status::Ok, "the new owner gives the publisher back") && ok;
    const Result<uint32_t> afterTransfer = dsmAgent.Read(subscription, read.value(), page, dcos::kPoll);
    ok = check(shell, afterTransfer.ok() && wordOf(page, 0) == 77, "the new owner's page is read") && ok;

    // Interrupt handlers may write and poll, but not wait, create or open.
    ok = checkStatus(shell, systemAgent.InstallISR(target_test::spareLine(), dsmIsrRoutine, nullptr), Status::Ok, "InstallISR") && ok;
    target_test::raiseSpareLine();
    ok = checkStatus(shell, systemAgent.RemoveISR(target_test::spareLine()), Status::Ok, "RemoveISR") && ok;
    ok = checkStatus(shell, dsmIsr.write, Status::Ok, "Write in an ISR") && ok;
    ok = checkStatus(shell, dsmIsr.readPoll, Status::Ok, "Read polls in an ISR") && ok;
    ok = check(shell, dsmIsr.readId != 0, "the ISR read its own page") && ok;
    ok = checkStatus(shell, dsmIsr.readWait, Status::InInterrupt, "Read may not wait in an ISR") && ok;
    ok = checkStatus(shell, dsmIsr.create, Status::InInterrupt, "Create in an ISR") && ok;
    ok = checkStatus(shell, dsmIsr.open, Status::InInterrupt, "Open in an ISR") && ok;

    // Forged, foreign, mistyped and stale ids.
    const ObjectId stalePublisher = dsmAgent.Create(nullptr, Visibility::Local).value();
    const ObjectId staleSubscription = dsmAgent.Open(stalePublisher).value();
    ok = checkStatus(shell, dsmAgent.Close(staleSubscription), Status::Ok, "Close") && ok;
    ok = checkStatus(shell, dsmAgent.Delete(stalePublisher), Status::Ok, "Delete") && ok;
    ok = rejectsBadIds(shell, "Write", ObjectType::DsmPublisher, ObjectType::DsmSubscription, publisher,
                       stalePublisher, [](ObjectId id) { return dsmAgent.Write(id, pageOf(0)).status(); }) && ok;
    ok = rejectsBadIds(shell, "Delete", ObjectType::DsmPublisher, ObjectType::MessagePort, publisher, stalePublisher,
                       [](ObjectId id) { return dsmAgent.Delete(id); }) && ok;
    ok = rejectsBadIds(shell, "Open", ObjectType::DsmPublisher, ObjectType::DsmSubscription, publisher,
                       stalePublisher, [](ObjectId id) { return dsmAgent.Open(id).status(); }) && ok;
    ok = rejectsBadIds(shell, "XferOwnership", ObjectType::DsmPublisher, ObjectType::Timer, publisher, stalePublisher,
                       [](ObjectId id) { return dsmAgent.XferOwnership(id, testTask()); }) && ok;
    // Nothing is read without a subscription: a publisher id is refused.
    ok = rejectsBadIds(shell, "Read", ObjectType::DsmSubscription, ObjectType::DsmPublisher, subscription,
                       staleSubscription, [](ObjectId id) {
                           DsmPage p{};
                           return dsmAgent.Read(id, dcos::kNoDsmData, p, dcos::kPoll).status();
                       }) && ok;
    ok = rejectsBadIds(shell, "Close", ObjectType::DsmSubscription, ObjectType::Task, subscription, staleSubscription,
                       [](ObjectId id) { return dsmAgent.Close(id); }) && ok;

    // Full tables, AddObjects and AddSubscribers.
    ok = fillTable(shell, "publishers", dcos::internal::kPublisherCapacity,
                   [] { return dsmAgent.Create(nullptr, Visibility::Local); },
                   [](size_t count) { return dsmAgent.AddObjects(count); },
                   [](ObjectId id) { (void)dsmAgent.Delete(id); }) && ok;
    ok = fillTable(shell, "subscriptions", dcos::internal::kSubscriptionCapacity,
                   [] { return dsmAgent.Open(sharedPublisher); },
                   [](size_t count) { return dsmAgent.AddSubscribers(count); },
                   [](ObjectId id) { (void)dsmAgent.Close(id); }) && ok;

    // Deleting the publisher invalidates the subscription; Close still works.
    ok = checkStatus(shell, dsmAgent.Delete(publisher), Status::Ok, "Delete the publisher") && ok;
    ok = checkStatus(shell, dsmAgent.Read(subscription, dcos::kNoDsmData, page, dcos::kPoll).status(),
                     Status::Deleted, "Read after the publisher was deleted") && ok;
    ok = checkStatus(shell, dsmAgent.Close(subscription), Status::Ok, "Close after the publisher was deleted") && ok;
    ok = checkStatus(shell, dsmAgent.Write(publisher, pageOf(1)).status(), Status::StaleId,
                     "Write to a deleted publisher") && ok;
    return ok;
}

DCOS_TARGET_TEST(dsmPrimitivesTest, "dsmprims", "distributed shared memory: every primitive with its errors",
                 dsmPrimitives);

// --- Distributed shared memory: Read at once, wait, time-out, Delete ---------------------------

ObjectId readPublisher;
volatile uint32_t readerLastSeen = 0;
struct ReaderOutcome {
    Status status;
    uint32_t dataId;
    uint32_t value;
};
ReaderOutcome readerOutcomes[2];

void waitingReaderEntry(uintptr_t index)
{
    const Result<ObjectId> subscription = dsmAgent.Open(readPublisher);
    DsmPage page{};
    const Result<uint32_t> read = dsmAgent.Read(subscription.value(), readerLastSeen, page, dcos::kWaitForever);
    readerOutcomes[index] = ReaderOutcome{read.status(), read.ok() ? read.value() : 0,
                                          isUniform(page) ? wordOf(page, 0) : 0xBAD};
    Trace::record(static_cast<char>('A' + index));
    if (read.status() == Status::Deleted) {
        // The subscription is dead too; only Close is left.
        const Status again = dsmAgent.Read(subscription.value(), 0, page, dcos::kPoll).status();
        Trace::record(again == Status::Deleted ? 'd' : '?');
    }
    (void)dsmAgent.Close(subscription.value());
    finished();
}

bool dsmRead(shell::Shell& shell)
{
    readPublisher = dsmAgent.Create("read-pub", Visibility::Local).value();
    const ObjectId subscription = dsmAgent.Open(readPublisher).value();
    DsmPage page{};
    bool ok = check(shell, !readPublisher.isNull() && !subscription.isNull(), "create and open");

    // Newer data is returned at once; the same identifier polls or waits.
    const uint32_t first = dsmAgent.Write(readPublisher, pageOf(1000)).value();
    const uint64_t atOnce = dcos::timerAgent.Uptime();
    const Result<uint32_t> immediate = dsmAgent.Read(subscription, dcos::kNoDsmData, page, 50 * kMillisecond);
    ok = check(shell, immediate.ok() && immediate.value() == first && wordOf(page, 0) == 1000,
               "newer data is returned") && ok;
    ok = check(shell, dcos::timerAgent.Uptime() - atOnce < kMillisecond, "at once") && ok;
    ok = checkStatus(shell, dsmAgent.Read(subscription, first, page, dcos::kPoll).status(), Status::WouldBlock,
                     "poll with nothing newer") && ok;
    const uint64_t before = dcos::timerAgent.Uptime();
    ok = checkStatus(shell, dsmAgent.Read(subscription, first, page, 10 * kMillisecond).status(), Status::Timeout,
                     "time-out with nothing newer") && ok;
    const uint64_t waited = dcos::timerAgent.Uptime() - before;
    shell.print("waited %llu ns for a 10 ms time-out\r\n", static_cast<unsigned long long>(waited));
    ok = check(shell, waited >= 10 * kMillisecond && waited <= 12 * kMillisecond, "a time-out of 10 ms") && ok;
    const uint32_t second = dsmAgent.Write(readPublisher, pageOf(2000)).value();
    ok = check(shell, second != first, "each Write gives a new identifier") && ok;
    const Result<uint32_t> skipped = dsmAgent.Read(subscription, dcos::kNoDsmData, page, dcos::kPoll);
    ok = check(shell, skipped.ok() && skipped.value() == second && wordOf(page, 0) == 2000,
               "a reader behind gets the latest page") && ok;

    // Two readers wait; one Write wakes both with its page.
    Trace::clear();
    readerLastSeen = second;
    ok = check(shell, !spawn("reader-a", 10, waitingReaderEntry, 0).isNull(), "create reader A") && ok;
    ok = check(shell, !spawn("reader-b", 11, waitingReaderEntry, 1).isNull(), "create reader B") && ok;
    Trace::record('w');
    const uint32_t third = dsmAgent.Write(readPublisher, pageOf(3000)).value();
    Trace::record('W');
    ok = waitForDone(shell, 2) && ok;
    for (const ReaderOutcome& outcome : readerOutcomes) {
        ok = checkStatus(shell, outcome.status, Status::Ok, "a waiting reader is woken by Write") && ok;
        ok = check(shell, outcome.dataId == third && outcome.value == 3000, "with the new page and identifier") && ok;
    }
    ok = Trace::expect(shell, "wABW") && ok;

    // Deleting the publisher wakes its waiting readers with Deleted.
    Trace::clear();
    readerLastSeen = third;
    ok = check(shell, !spawn("reader-a", 10, waitingReaderEntry, 0).isNull(), "create reader A") && ok;
    ok = check(shell, !spawn("reader-b", 11, waitingReaderEntry, 1).isNull(), "create reader B") && ok;
    ok = checkStatus(shell, dsmAgent.Delete(readPublisher), Status::Ok, "Delete with readers waiting") && ok;
    ok = waitForDone(shell, 2) && ok;
    for (const ReaderOutcome& outcome : readerOutcomes) {
        ok = checkStatus(shell, outcome.status, Status::Deleted, "a waiting reader is woken with Deleted") && ok;
    }
    ok = Trace::expect(shell, "AdBd") && ok;
    ok = checkStatus(shell, dsmAgent.Read(subscription, third, page, dcos::kPoll).status(), Status::Deleted,
                     "the test task's subscription is invalid too") && ok;
    ok = checkStatus(shell, dsmAgent.Close(subscription), Status::Ok, "Close") && ok;
    return ok;
}

DCOS_TARGET_TEST(dsmReadTest, "dsmread", "DSM Read: at once when newer, poll, time-out, woken by Write and Delete",
                 dsmRead);

// --- DSM readers racing a writer with no torn page ---------------------------------------

namespace race {

constexpr unsigned kWrites = 1500;
constexpr unsigned kReaders = 3;

ObjectId publisher;
volatile uint32_t nextValue = 0;
volatile unsigned writeFailures = 0;
volatile unsigned isrWrites = 0;
volatile unsigned isrFailures = 0;
volatile unsigned tornPages = 0;
volatile unsigned notNewer = 0;
volatile unsigned unexpected = 0;
volatile unsigned reads[kReaders] = {};

uint32_t takeValue()
{
    arch_x86::InterruptGuard guard;
    nextValue = nextValue + 1;
    return nextValue;
}

void writingIsr(void*)
{
    if (dsmAgent.Write(publisher, pageOf(takeValue())).ok()) {
        isrWrites = isrWrites + 1;
    } else {
        isrFailures = isrFailures + 1;
    }
}

void writerEntry(uintptr_t)
{
    for (unsigned i = 1; i <= kWrites; ++i) {
        if (!dsmAgent.Write(publisher, pageOf(takeValue())).ok()) {
            writeFailures = writeFailures + 1;
        }
        if (i % 7 == 0) {
            (void)dcos::schedulerAgent.Yield();
        }
        if (i % 50 == 0) {
            target_test::raiseSpareLine();
        }
        if (i % 50 == 0) {
            (void)taskAgent.SleepFor(kMillisecond); // Lets the less urgent reader run.
        }
    }
    // Deleting the publisher ends the readers: their Read returns Deleted.
    if (dsmAgent.Delete(publisher) != Status::Ok) {
        unexpected = unexpected + 1;
    }
    finished();
}

// Reader 0 waits without a time-out, reader 1 polls (raising the writing ISR
// now and then, and sleeping now and then so the least urgent reader gets
// the CPU too), reader 2 waits with a time-out. Each owns the subscription
// the test task opened for it.
ObjectId subscriptions[kReaders];

void readerEntry(uintptr_t index)
{
    const ObjectId subscription = subscriptions[index];
    uint32_t last = dcos::kNoDsmData;
    unsigned emptyPolls = 0;
    for (;;) {
        DsmPage page{};
        const uint64_t timeout = index == 0 ? dcos::kWaitForever : index == 1 ? dcos::kPoll : 5 * kMillisecond;
        const Result<uint32_t> read = dsmAgent.Read(subscription, last, page, timeout);
        if (read.status() == Status::Deleted) {
            break;
        }
        if (read.status() == Status::WouldBlock || read.status() == Status::Timeout) {
            if (index == 1) {
                ++emptyPolls;
                if (emptyPolls % 4 == 0) {
                    target_test::raiseSpareLine();
                }
                if (emptyPolls % 8 == 0) {
                    (void)taskAgent.SleepFor(kMillisecond);
                } else {
                    (void)dcos::schedulerAgent.Yield();
                }
            }
            continue;
        }
        if (!read.ok()) {
            unexpected = unexpected + 1;
            break;
        }
        if (!isUniform(page) || wordOf(page, 0) == 0) {
            tornPages = tornPages + 1;
        }
        if (last != dcos::kNoDsmData && static_cast<int32_t>(read.value() - last) <= 0) {
            notNewer = notNewer + 1;
        }
        last = read.value();
        reads[index] = reads[index] + 1;
    }
    if (dsmAgent.Close(subscription) != Status::Ok) {
        unexpected = unexpected + 1;
    }
    finished();
}

} // namespace race

bool dsmRace(shell::Shell& shell)
{
    race::publisher = dsmAgent.Create("race", Visibility::Local).value();
    bool ok = check(shell, !race::publisher.isNull(), "create the publisher");
    ok = checkStatus(shell, systemAgent.InstallISR(target_test::spareLine(), race::writingIsr, nullptr), Status::Ok,
                     "InstallISR") && ok;
    const size_t subscriptionsBefore = DsmManager::subscriptionCount();
    {
        HoldScheduling hold;
        // The writer and reader 1 share priority 20 with time slicing; reader
        // 0 is more urgent, reader 2 less.
        const ObjectId writer = spawn("dsm-writer", 20, race::writerEntry, 0, true);
        ok = check(shell, !writer.isNull(), "create the writer") && ok;
        ok = checkStatus(shell, dsmAgent.XferOwnership(race::publisher, writer), Status::Ok,
                         "give the writer the publisher") && ok;
        const char* names[race::kReaders] = {"dsm-reader0", "dsm-reader1", "dsm-reader2"};
        const uint8_t priorities[race::kReaders] = {18, 20, 22};
        for (unsigned i = 0; i < race::kReaders; ++i) {
            race::subscriptions[i] = dsmAgent.Open(race::publisher).value();
            const ObjectId reader = spawn(names[i], priorities[i], race::readerEntry, i, true);
            ok = check(shell, !reader.isNull(), "create a reader") && ok;
            ok = checkStatus(shell, dsmAgent.XferOwnership(race::subscriptions[i], reader), Status::Ok,
                             "give the reader its subscription") && ok;
        }
    }
    ok = waitForDone(shell, 1 + race::kReaders, 20000 * kMillisecond) && ok;
    ok = checkStatus(shell, systemAgent.RemoveISR(target_test::spareLine()), Status::Ok, "RemoveISR") && ok;
    shell.print("writes: %u by the task, %u by the ISR; reads: %u, %u, %u; torn %u, not newer %u, unexpected %u\r\n",
                race::kWrites, race::isrWrites, race::reads[0], race::reads[1], race::reads[2], race::tornPages,
                race::notNewer, race::unexpected);
    ok = check(shell, race::writeFailures == 0 && race::isrFailures == 0, "every Write succeeded") && ok;
    ok = check(shell, race::isrWrites > 0, "the ISR wrote too") && ok;
    ok = check(shell, race::tornPages == 0, "no reader saw a torn page") && ok;
    ok = check(shell, race::notNewer == 0, "every Read returned a newer identifier") && ok;
    ok = check(shell, race::unexpected == 0, "no unexpected status") && ok;
    for (unsigned i = 0; i < race::kReaders; ++i) {
        ok = check(shell, race::reads[i] >= 5, "every reader read") && ok;
    }
    ok = check(shell, DsmManager::subscriptionCount() == subscriptionsBefore, "every subscription was closed") && ok;
    return ok;
}

DCOS_TARGET_TEST(dsmRaceTest, "dsmrace", "DSM readers racing a writer and an ISR see no torn page", dsmRace);

// --- Recovery of a dead task's ports, publishers and subscriptions ------------------------

ObjectId doomedPort;
ObjectId doomedPublisher;
ObjectId survivingPublisher;
volatile bool doomedReady = false;

// Owns a port, a publisher, a subscription to its own publisher and one to
// the test task's; then waits in Read on the test task's publisher (variant
// 0, to be killed) or returns (variant 1, a normal end).
void doomedOwnerEntry(uintptr_t variant)
{
    doomedPort = messagePortAgent.Create("doomed-port", Visibility::Local).value();
    doomedPublisher = dsmAgent.Create("doomed-pub", Visibility::Local).value();
    const ObjectId own = dsmAgent.Open(doomedPublisher).value();
    const ObjectId other = dsmAgent.Open(survivingPublisher).value();
    (void)dsmAgent.Write(doomedPublisher, pageOf(5));
    doomedReady = !doomedPort.isNull() && !doomedPublisher.isNull() && !own.isNull() && !other.isNull();
    if (variant == 0) {
        DsmPage page{};
        (void)dsmAgent.Read(other, dcos::kNoDsmData, page, dcos::kWaitForever);
    } else {
        (void)taskAgent.ReceiveEvent(1, dcos::EventWait::Any, dcos::kWaitForever);
    }
}

bool recovery(shell::Shell& shell)
{
    bool ok = true;
    survivingPublisher = dsmAgent.Create("survivor", Visibility::Local).value();
    for (uintptr_t variant = 0; variant < 2; ++variant) {
        const size_t buffersBefore = freeBuffers();
        const size_t portsBefore = PortManager::portCount();
        const size_t publishersBefore = DsmManager::publisherCount();
        const size_t subscriptionsBefore = DsmManager::subscriptionCount();
        doomedReady = false;
        const ObjectId owner = spawn(variant == 0 ? "doomed-killed" : "doomed-ended", 10, doomedOwnerEntry, variant);
        ok = check(shell, !owner.isNull() && doomedReady, "the owner created its objects") && ok;
        // The test task subscribes to the doomed publisher and fills the port.
        const ObjectId watcher = dsmAgent.Open(doomedPublisher).value();
        for (uint32_t i = 0; i < 5; ++i) {
            ok = checkStatus(shell, messagePortAgent.Send(doomedPort, messageOf(i), static_cast<int>(i)), Status::Ok,
                             "Send to the doomed port") && ok;
        }
        ok = check(shell, freeBuffers() == buffersBefore - 5, "five messages are queued") && ok;
        ok = check(shell, PortManager::portCount() == portsBefore + 1 &&
                              DsmManager::publisherCount() == publishersBefore + 1 &&
                              DsmManager::subscriptionCount() == subscriptionsBefore + 3,
                   "a port, a publisher and three subscriptions exist") && ok;
        if (variant == 0) {
            ok = checkStatus(shell, taskAgent.KillTask(owner), Status::Ok, "KillTask while it waits in Read") && ok;
        } else {
            (void)taskAgent.PostEvent(owner, 1); // It returns from its entry and ends.
            (void)taskAgent.SleepFor(2 * kMillisecond);
        }
        shell.print("%s: buffers free %u->%u, ports %u->%u, publishers %u->%u, subscriptions %u->%u\r\n",
                    variant == 0 ? "KillTask" : "end", static_cast<unsigned>(buffersBefore),
                    static_cast<unsigned>(freeBuffers()), static_cast<unsigned>(portsBefore),
                    static_cast<unsigned>(PortManager::portCount()), static_cast<unsigned>(publishersBefore),
                    static_cast<unsigned>(DsmManager::publisherCount()), static_cast<unsigned>(subscriptionsBefore),
                    static_cast<unsigned>(DsmManager::subscriptionCount()));
        ok = check(shell, freeBuffers() == buffersBefore, "the queued buffers came back") && ok;
        ok = check(shell, PortManager::portCount() == portsBefore, "the port was deleted") && ok;
        ok = check(shell, DsmManager::publisherCount() == publishersBefore, "the publisher was deleted") && ok;
        // The watcher's subscription stays until it is closed.
        ok = check(shell, DsmManager::subscriptionCount() == subscriptionsBefore + 1,
                   "the owner's subscriptions were closed") && ok;
        ok = checkStatus(shell, messagePortAgent.Send(doomedPort, messageOf(0), 0), Status::StaleId,
                         "the port's id is stale") && ok;
        ok = checkStatus(shell, dsmAgent.Open(doomedPublisher).status(), Status::StaleId,
                         "the publisher's id is stale") && ok;
        DsmPage page{};
        ok = checkStatus(shell, dsmAgent.Read(watcher, dcos::kNoDsmData, page, dcos::kPoll).status(), Status::Deleted,
                         "a subscription to the dead task's publisher reports Deleted") && ok;
        ok = checkStatus(shell, dsmAgent.Close(watcher), Status::Ok, "Close it") && ok;
        // The dead reader left the surviving publisher's wait queue: a
        // Write wakes nobody and the publisher goes on working.
        const Result<uint32_t> written = dsmAgent.Write(survivingPublisher, pageOf(9));
        ok = check(shell, written.ok(), "the surviving publisher still works") && ok;
        ok = checkStatus(shell, taskAgent.Suspend(owner), Status::StaleId, "the dead task's id is stale") && ok;
    }
    ok = checkStatus(shell, dsmAgent.Delete(survivingPublisher), Status::Ok, "Delete the surviving publisher") && ok;
    return ok;
}

DCOS_TARGET_TEST(portDsmRecoveryTest, "portdsmrecovery",
                 "a dead task's ports (with queued messages), publishers and subscriptions are recovered", recovery);

} // namespace

} // namespace target_test
