// The `remote` console command of the test image: the primitives that
// remote transactions carry, called from the console task by id, so that an
// emulator test (tests_renode/test_remote_transactions.py) runs the same
// calls on a local object and on another board's object and compares the
// results. Each line it prints starts with a tag the test reads:
//
//     RSEM <id>                   a semaphore was created
//     RTASK <id>                  the listener task was created, or the console's id (self)
//     RTIMER <id>                 a timer was created
//     RRES <status> <value> <us>  a primitive's status, its value, and the
//                                 microseconds of uptime it took
//     RGOT <events> <signals>     what the listener has received so far
//     RHOG <ms>                   the busy task ran that long
//     RKILL <status>              KillTask's status
//     RHALT                       the node stops for good (halt)
//     RPORT <id>                  the porter's port was created
//     RPOOL <id>, RHEAP <id>      a global pool (eight 64-byte buffers) or
//                                 heap (4 KiB) was created, to be used from
//                                 the other node of the dual-Pentium board
//     RPGOT <count> <priorities> <last message>
//                                 what the porter has received: how many
//                                 messages, the first byte of each of the
//                                 first eight in the order received, and
//                                 the last one's sixteen bytes, in hex
//
// The listener is a task that collects every event posted and every signal
// sent to it; the hog is a task that keeps the processor busy at a chosen
// priority, to show that a request of lower priority waits for it.
#include "KernelTestSupport.hpp"

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/GregorianCalendar.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/IdText.hpp>

#include <arch_x86/Cpu.hpp>
#include <bsp/Board.hpp>

#include <runtime/Text.hpp>
#include <shell/ShellCommand.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::semaphoreAgent;
using dcos::taskAgent;
using dcos::timerAgent;
using runtime::textEquals;
using shell::CommandResult;

constexpr uint64_t kNsPerMs = 1'000'000;

volatile uint32_t listenerEvents = 0;
volatile uint32_t listenerSignals = 0;

void listenerSignal(unsigned signal) { listenerSignals = listenerSignals | (1u << signal); }

// The areas of the pool and heap `remote pool` and `remote heap` create;
// one of each at a time.
constexpr size_t kLentBufferBytes = 64;
constexpr size_t kLentBuffers = 8;
alignas(8) uint8_t lentPoolArea[dcos::BufferPoolAgent::AreaBytes(kLentBufferBytes, kLentBuffers)];
alignas(8) uint8_t lentHeapArea[4096];

void listenerEntry(uintptr_t)
{
    (void)taskAgent.SetSignalHandler(listenerSignal);
    for (;;) {
        const Result<uint32_t> got = taskAgent.ReceiveEvent(0xFFFFFFFF, dcos::EventWait::Any, dcos::kWaitForever);
        if (got.ok()) {
            listenerEvents = listenerEvents | got.value();
        }
    }
}

// The porter: a task that creates the global port "inbox", then receives
// from it for ever (only a port's owner receives), keeping what came.
volatile uint32_t porterPort = 0;
volatile uint32_t porterCount = 0;
uint8_t porterFirstBytes[8];
dcos::Message porterLast{};

void porterEntry(uintptr_t)
{
    const Result<ObjectId> port = dcos::messagePortAgent.Create("inbox", dcos::Visibility::Global);
    if (!port.ok()) {
        return;
    }
    porterPort = port.value().raw();
    for (;;) {
        dcos::Message message;
        if (dcos::messagePortAgent.Receive(port.value(), message, dcos::kWaitForever) != Status::Ok) {
            continue;
        }
        if (porterCount < sizeof porterFirstBytes) {
            porterFirstBytes[porterCount] = message.bytes[0];
        }
        porterLast = message;
        porterCount = porterCount + 1;
    }
}

// The waiters: tasks that acquire a semaphore (remote or not) for ever.
volatile uint32_t waiterStatuses = 0; // Bit n: a waiter ended with status n.

void waiterEntry(uintptr_t semaphore)
{
    const Status status = semaphoreAgent.Acquire(ObjectId::fromRaw(static_cast<uint32_t>(semaphore)),
                                                 dcos::kWaitForever);
    waiterStatuses = waiterStatuses | (1u << static_cast<unsigned>(status));
}

volatile uint64_t hogUntilNs = 0;
volatile uint64_t hogRanNs = 0;

void hogEntry(uintptr_t)
{
    const uint64_t start = timerAgent.Uptime();
    while (timerAgent.Uptime() < hogUntilNs) {
    }
    hogRanNs = timerAgent.Uptime() - start;
}

// Prints "<tag> <id>" for a created object, or the error; the command's result.
CommandResult reportCreated(shell::Shell& shell, const char* tag, const Result<ObjectId>& created)
{
    if (!created.ok()) {
        shell.print("error: %s\r\n", dcos::statusName(created.status()));
        return CommandResult::Failed;
    }
    shell.print("%s %s\r\n", tag, dcos::internal::IdText(created.value()).c_str());
    return CommandResult::Ok;
}

Result<ObjectId> createTask(const char* name, unsigned long priority, dcos::TaskEntry entry)
{
    dcos::TaskAttributes attributes;
    attributes.name = name;
    attributes.priority = static_cast<uint8_t>(priority);
    return taskAgent.Create(attributes, entry, 0);
}

void printResult(shell::Shell& shell, Status status, uint32_t value, uint64_t startNs)
{
    const uint64_t us = (timerAgent.Uptime() - startNs) / 1000;
    shell.print("RRES %s %lu %lu\r\n", dcos::statusName(status), static_cast<unsigned long>(value),
                static_cast<unsigned long>(us));
}

CommandResult remote(shell::Shell& shell, int argc, char** argv)
{
    if (argc < 2) {
        return CommandResult::UsageError;
    }
    const char* const verb = argv[1];
    unsigned long number = 0;
    ObjectId id;
    if (textEquals(verb, "sem") && (argc == 3 || argc == 4)) {
        dcos::SemaphoreAttributes attributes;
        attributes.visibility = dcos::Visibility::Global;
        if (textEquals(argv[2], "binary")) {
            attributes.kind = dcos::SemaphoreKind::Binary;
            attributes.initialCount = 1;
        } else if (shell::Shell::parseUnsigned(argv[2], number)) {
            attributes.kind = dcos::SemaphoreKind::Counting;
            attributes.initialCount = static_cast<uint32_t>(number);
            unsigned long maximum = 0xFFFFFFFF;
            if (argc == 4 && !shell::Shell::parseUnsigned(argv[3], maximum)) {
                return CommandResult::UsageError;
            }
            attributes.maximumCount = static_cast<uint32_t>(maximum);
        } else {
            return CommandResult::UsageError;
        }
        return reportCreated(shell, "RSEM", semaphoreAgent.Create(attributes));
    }
    if (textEquals(verb, "named") && argc == 4) {
        // named <name> local|regional|global: a counting semaphore (count 1) with that name and visibility.
        dcos::SemaphoreAttributes attributes;
        attributes.name = argv[2];
        attributes.kind = dcos::SemaphoreKind::Counting;
        if (textEquals(argv[3], "local")) {
            attributes.visibility = dcos::Visibility::Local;
        } else if (textEquals(argv[3], "regional")) {
            attributes.visibility = dcos::Visibility::Regional;
        } else if (textEquals(argv[3], "global")) {
            attributes.visibility = dcos::Visibility::Global;
        } else {
            return CommandResult::UsageError;
        }
        return reportCreated(shell, "RSEM", semaphoreAgent.Create(attributes));
    }
    if (textEquals(verb, "pool") && argc == 2) {
        return reportCreated(shell, "RPOOL",
                             dcos::bufferPoolAgent.Create(lentPoolArea, sizeof lentPoolArea, kLentBufferBytes, "lent",
                                                          dcos::Visibility::Global));
    }
    if (textEquals(verb, "heap") && argc == 2) {
        return reportCreated(shell, "RHEAP",
                             dcos::heapAgent.Create(lentHeapArea, sizeof lentHeapArea, "lentheap",
                                                    dcos::Visibility::Global));
    }
    if ((textEquals(verb, "peek") && argc == 3) || (textEquals(verb, "poke") && argc == 4)) {
        // A 32-bit word of memory at an address a buffer or segment call
        // gave, read or written from this node: the proof that the two
        // nodes of the board see the same memory there.
        unsigned long address = 0, word = 0;
        if (!shell::Shell::parseUnsigned(argv[2], address) || (address & 3) != 0 || address < 0x1000 ||
            (argc == 4 && !shell::Shell::parseUnsigned(argv[3], word))) {
            return CommandResult::UsageError;
        }
        volatile uint32_t* const at = reinterpret_cast<volatile uint32_t*>(address);
        if (argc == 4) {
            *at = static_cast<uint32_t>(word);
        }
        shell.print("RRES ok %lu 0\r\n", static_cast<unsigned long>(*at));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "delete") && argc == 3 && parseObjectId(argv[2], id)) {
        shell.print("RRES %s 0 0\r\n", dcos::statusName(semaphoreAgent.Delete(id)));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "name") && argc == 4) {
        // name <kind> <name>: NameToObject of that agent, local first, then the other nodes.
        const char* const kind = argv[2];
        const uint64_t start = timerAgent.Uptime();
        Result<ObjectId> found = Status::InvalidArgument;
        if (textEquals(kind, "task")) {
            found = taskAgent.NameToObject(argv[3]);
        } else if (textEquals(kind, "semaphore")) {
            found = semaphoreAgent.NameToObject(argv[3]);
        } else if (textEquals(kind, "publisher")) {
            found = dcos::dsmAgent.NameToObject(argv[3]);
        } else if (textEquals(kind, "timer")) {
            found = timerAgent.NameToObject(argv[3]);
        } else {
            return CommandResult::UsageError;
        }
        printResult(shell, found.status(), found.ok() ? found.value().raw() : 0, start);
        return CommandResult::Ok;
    }
    if (textEquals(verb, "halt") && argc == 2) {
        // A node that dies without a word, as a processor that hangs does:
        // interrupts off and halted for good, so it answers nothing, sends
        // nothing and tells no peer. The other node of a dual-processor board
        // runs on; its requests to this node meet the remote watchdog.
        shell.print("RHALT\r\n");
        bsp::consoleFlush();
        arch_x86::disableInterrupts();
        for (;;) {
            arch_x86::haltUntilInterrupt();
        }
    }
    if (textEquals(verb, "self") && argc == 2) {
        shell.print("RTASK %s\r\n", dcos::internal::IdText(taskAgent.IdOfSelf()).c_str());
        return CommandResult::Ok;
    }
    if (textEquals(verb, "timer") && argc == 2) {
        return reportCreated(shell, "RTIMER", timerAgent.Create(nullptr, dcos::Visibility::Global));
    }
    if (textEquals(verb, "give") && argc == 4 && parseObjectId(argv[2], id)) {
        // give <timer> <task>: XferOwnership of a timer, to a task of this node or another.
        ObjectId owner;
        if (!parseObjectId(argv[3], owner)) {
            return CommandResult::UsageError;
        }
        const uint64_t start = timerAgent.Uptime();
        printResult(shell, timerAgent.XferOwnership(id, owner), 0, start);
        return CommandResult::Ok;
    }
    if (textEquals(verb, "alarm") && argc == 6 && parseObjectId(argv[2], id)) {
        // alarm <timer> watchdog|periodic|day <ms> <events>: the alarm, its
        // events posted to the timer's owner; day: the time of day <ms> from now.
        unsigned long ms = 0;
        unsigned long events = 0;
        if (!shell::Shell::parseUnsigned(argv[4], ms) || !shell::Shell::parseUnsigned(argv[5], events)) {
            return CommandResult::UsageError;
        }
        const dcos::AlarmNotification notification = dcos::AlarmNotification::event(static_cast<uint32_t>(events));
        const uint64_t start = timerAgent.Uptime();
        Status status;
        if (textEquals(argv[3], "watchdog")) {
            status = timerAgent.SetWatchDogAlarm(id, ms * kNsPerMs, notification);
        } else if (textEquals(argv[3], "periodic")) {
            status = timerAgent.SetPeriodicAlarm(id, ms * kNsPerMs, notification);
        } else if (textEquals(argv[3], "day")) {
            const Result<dcos::DateTime> now = timerAgent.GetSystemClock();
            const Result<uint64_t> nowNs =
                now.ok() ? dcos::GregorianCalendar::toNanoseconds(now.value()) : Result<uint64_t>(now.status());
            status = nowNs.ok() ? timerAgent.SetDayClockAlarm(
                                      id, dcos::GregorianCalendar::fromNanoseconds(nowNs.value() + ms * kNsPerMs),
                                      notification)
                                : nowNs.status();
        } else {
            return CommandResult::UsageError;
        }
        printResult(shell, status, 0, start);
        return CommandResult::Ok;
    }
    if (textEquals(verb, "cancel") && argc == 3 && parseObjectId(argv[2], id)) {
        const uint64_t start = timerAgent.Uptime();
        printResult(shell, timerAgent.CancelAlarm(id), 0, start);
        return CommandResult::Ok;
    }
    if (textEquals(verb, "events") && argc == 3 && shell::Shell::parseUnsigned(argv[2], number)) {
        // events <ms>: the console task's own events (an alarm's owner's), any of bits 1 to 15, waited for
        // (bit 0 is the console's input event).
        const uint64_t start = timerAgent.Uptime();
        const Result<uint32_t> got =
            taskAgent.ReceiveEvent(0xFFFE, dcos::EventWait::Any, number == 0 ? dcos::kPoll : number * kNsPerMs);
        printResult(shell, got.status(), got.ok() ? got.value() : 0, start);
        return CommandResult::Ok;
    }
    if (textEquals(verb, "listener") && argc == 2) {
        return reportCreated(shell, "RTASK", createTask("listener", 10, listenerEntry));
    }
    if (textEquals(verb, "waiter") && argc == 3 && parseObjectId(argv[2], id)) {
        dcos::TaskAttributes attributes;
        attributes.name = "waiter";
        attributes.priority = 12;
        return reportCreated(shell, "RTASK", taskAgent.Create(attributes, waiterEntry, id.raw()));
    }
    if (textEquals(verb, "kill") && argc == 3 && parseObjectId(argv[2], id)) {
        shell.print("RKILL %s\r\n", dcos::statusName(taskAgent.KillTask(id)));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "port") && argc == 2) {
        // More urgent than the console: it has made its port when this returns.
        const Result<ObjectId> porter = createTask("porter", 9, porterEntry);
        if (!porter.ok() || porterPort == 0) {
            shell.print("error: %s\r\n", dcos::statusName(porter.ok() ? Status::NoMemory : porter.status()));
            return CommandResult::Failed;
        }
        shell.print("RPORT %s\r\n", dcos::internal::IdText(ObjectId::fromRaw(porterPort)).c_str());
        return CommandResult::Ok;
    }
    if (textEquals(verb, "portgot") && argc == 2) {
        shell.print("RPGOT %lu ", static_cast<unsigned long>(porterCount));
        const uint32_t listed = porterCount < sizeof porterFirstBytes ? porterCount : sizeof porterFirstBytes;
        for (uint32_t i = 0; i < listed; ++i) {
            shell.print("%02x", porterFirstBytes[i]);
        }
        shell.print(listed == 0 ? "- " : " ");
        for (uint8_t byte : porterLast.bytes) {
            shell.print("%02x", byte);
        }
        shell.print("\r\n");
        return CommandResult::Ok;
    }
    if (textEquals(verb, "got") && argc == 2) {
        shell.print("RGOT 0x%lx 0x%lx\r\n", static_cast<unsigned long>(listenerEvents),
                    static_cast<unsigned long>(listenerSignals));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "hog") && argc == 4) {
        unsigned long priority, ms;
        if (!shell::Shell::parseUnsigned(argv[2], priority) || priority > dcos::kLowestPriority ||
            !shell::Shell::parseUnsigned(argv[3], ms)) {
            return CommandResult::UsageError;
        }
        hogUntilNs = timerAgent.Uptime() + ms * kNsPerMs;
        hogRanNs = 0;
        const Result<ObjectId> created = createTask("hog", priority, hogEntry);
        if (!created.ok()) {
            shell.print("error: %s\r\n", dcos::statusName(created.status()));
            return CommandResult::Failed;
        }
        // The hog runs now if it is more urgent than the console; the line
        // comes when the console runs again.
        shell.print("RHOG %lu\r\n", static_cast<unsigned long>(hogRanNs / kNsPerMs));
        return CommandResult::Ok;
    }
    // The primitives, at the console's priority or at "at=P" (the request's
    // priority, which the serving node inherits). "tick" begins the call just
    // after a tick of the system clock: at 1 Mbit/s a round trip is well
    // under the default tick period of 1 ms, so no tick interrupt lands in
    // the call on either node (the lab's boards boot in step), and the
    // remote bench's instruction counts are the same on every call.
    int first = 2;
    unsigned long priority = 0xFF;
    bool afterTick = false;
    for (; first < argc; ++first) {
        if (argv[first][0] == 'a' && argv[first][1] == 't' && argv[first][2] == '=') {
            if (!shell::Shell::parseUnsigned(argv[first] + 3, priority) || priority > dcos::kLowestPriority) {
                return CommandResult::UsageError;
            }
        } else if (textEquals(argv[first], "tick")) {
            afterTick = true;
        } else {
            break;
        }
    }
    if (argc < first + 1 || !parseObjectId(argv[first], id)) {
        return CommandResult::UsageError;
    }
    const int extra = argc - first - 1;
    unsigned long argument = 0;
    if (extra == 1 && !shell::Shell::parseUnsigned(argv[first + 1], argument)) {
        return CommandResult::UsageError;
    }
    const ObjectId self = taskAgent.IdOfSelf();
    uint8_t oldPriority = 0;
    if (priority != 0xFF) {
        const Result<uint8_t> current = taskAgent.GetPriority(self);
        oldPriority = current.ok() ? current.value() : 0;
        (void)taskAgent.ChangePriority(self, static_cast<uint8_t>(priority));
    }
    if (afterTick) {
        (void)taskAgent.SleepFor(1); // Wakes at the next tick.
    }
    const uint64_t start = timerAgent.Uptime();
    Status status = Status::InvalidArgument;
    uint32_t value = 0;
    bool known = true;
    if (textEquals(verb, "acquire") && extra == 1) {
        status = semaphoreAgent.Acquire(id, argument == 0xFFFFFFFF ? dcos::kWaitForever : argument * kNsPerMs);
    } else if (textEquals(verb, "release") && extra == 0) {
        status = semaphoreAgent.Release(id);
    } else if (textEquals(verb, "count") && extra == 0) {
        const Result<uint32_t> count = semaphoreAgent.GetCount(id);
        status = count.status();
        value = count.ok() ? count.value() : 0;
    } else if (textEquals(verb, "post") && extra == 1) {
        status = taskAgent.PostEvent(id, static_cast<uint32_t>(argument));
    } else if (textEquals(verb, "signal") && extra == 1) {
        status = taskAgent.SendSignal(id, static_cast<unsigned>(argument));
    } else if (textEquals(verb, "state") && extra == 0) {
        const Result<dcos::TaskState> state = taskAgent.GetState(id);
        status = state.status();
        value = state.ok() ? static_cast<uint32_t>(state.value()) : 0;
    } else if (textEquals(verb, "priority") && extra == 0) {
        const Result<uint8_t> taskPriority = taskAgent.GetPriority(id);
        status = taskPriority.status();
        value = taskPriority.ok() ? taskPriority.value() : 0;
    } else if (textEquals(verb, "send") && extra == 1) {
        // The message: sixteen bytes counting up from the argument's low
        // byte; its priority: the argument's second byte (0 to 31).
        dcos::Message message;
        for (size_t i = 0; i < dcos::kMessageSize; ++i) {
            message.bytes[i] = static_cast<uint8_t>(argument + i);
        }
        status = dcos::messagePortAgent.Send(id, message, static_cast<int>((argument >> 8) & 0xFF));
    } else if (textEquals(verb, "receive") && extra == 0) {
        dcos::Message message;
        status = dcos::messagePortAgent.Receive(id, message, dcos::kPoll);
    } else if (textEquals(verb, "alloc") && extra == 0) {
        const Result<void*> buffer = dcos::bufferPoolAgent.Allocate(id);
        status = buffer.status();
        value = buffer.ok() ? static_cast<uint32_t>(reinterpret_cast<uintptr_t>(buffer.value())) : 0;
    } else if (textEquals(verb, "free") && extra == 1) {
        status = dcos::bufferPoolAgent.Return(id, reinterpret_cast<void*>(argument));
    } else if (textEquals(verb, "halloc") && extra == 1) {
        const Result<void*> segment = dcos::heapAgent.Allocate(id, argument);
        status = segment.status();
        value = segment.ok() ? static_cast<uint32_t>(reinterpret_cast<uintptr_t>(segment.value())) : 0;
    } else if (textEquals(verb, "hfree") && extra == 1) {
        status = dcos::heapAgent.Return(id, reinterpret_cast<void*>(argument));
    } else if (textEquals(verb, "holder") && extra == 0) {
        const Result<ObjectId> holder = semaphoreAgent.GetHolder(id);
        status = holder.status();
        value = holder.ok() ? holder.value().raw() : 0;
    } else {
        known = false;
    }
    if (priority != 0xFF) {
        (void)taskAgent.ChangePriority(self, oldPriority);
    }
    if (!known) {
        return CommandResult::UsageError;
    }
    printResult(shell, status, value, start);
    return CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(
    remoteCommand, "remote", "call primitives by id, local or remote, for the lab's tests (test image only)",
    "remote sem <count> [max] | sem binary | named <name> local|regional|global | delete <semaphore> | "
    "name task|semaphore|publisher|timer <name> | listener | got | hog <priority> <ms> | waiter <id> | kill <task> | "
    "acquire [at=P] [tick] <id> <ms> | release [at=P] [tick] <id> | count [at=P] [tick] <id> | "
    "post [at=P] [tick] <id> <events> | signal [at=P] [tick] <id> <n> | state [at=P] [tick] <task> | "
    "priority [at=P] [tick] <task> | holder [at=P] [tick] <semaphore> | port | portgot | "
    "send [at=P] [tick] <port> <priority*256+first byte> | receive [tick] <port> | self | timer | "
    "give <timer> <task> | alarm <timer> watchdog|periodic|day <ms> <events> | cancel <timer> | events <ms> | halt | "
    "pool | heap | alloc <pool> | free <pool> <address> | halloc <heap> <bytes> | hfree <heap> <address> | "
    "peek <address> | poke <address> <word>",
    "  sem: a global semaphore; listener: a task that collects events and signals (got shows them)\r\n"
    "  hog: a task that keeps the processor busy at a priority for a time\r\n"
    "  waiter: a task that acquires the semaphore for ever; kill: KillTask\r\n"
    "  acquire ms: 0 polls, 4294967295 waits for ever; at=P calls at priority P; tick calls just after a tick\r\n"
    "  port: a task that owns the global port \"inbox\" and receives from it (portgot shows what came)\r\n"
    "  send: sixteen bytes counting up from the argument's low byte, at the priority in its second byte\r\n"
    "  timer: a global timer of the console; give: XferOwnership; alarm: its events to the owner; events: the console's\r\n"
    "  halt: this node stops for good, interrupts off, as a hung processor does\r\n"
    "  pool, heap: a global pool of eight 64-byte buffers, a global 4 KiB heap; alloc/free, halloc/hfree use them\r\n"
    "  peek, poke: a 32-bit word at an address such a call gave (value in RRES)\r\n"
    "  prints RRES <status> <value> <microseconds taken>",
    remote);

} // namespace target_test
