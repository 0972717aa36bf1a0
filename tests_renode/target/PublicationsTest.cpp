// The `pubsub` console command of the test image: publishers and
// subscribers across boards (tests_renode/test_publications.py,
// docs/protocols/publications.md).
//
// The publishing task writes pages whose four 32-bit words are derived
// from one counter (1, 2, 3, ...), so a subscriber can tell a whole page
// from a torn one and count what it missed. The subscribing task opens a
// subscription to a publisher by id, local or another board's, and reads
// every new page, waiting for it. What each line prints starts with a tag
// the test reads:
//
//     PPUB <publisher id>                        a publishing task began
//     PSUB <status> <received> <last> <repeats> <torn> <gaps> <deleted> <waits>
//                                                the subscriber's tally
//     RRES <status> <value> <us>                 a console call's result
//
// A repeat is a page whose counter is not above the last one read: a
// duplicate or an old page, which a subscriber must never see. Gaps count
// the writes skipped between two pages read; a subscriber slower than the
// publisher skips some by design (it reads the latest page), so the tests
// bound them only where the reader keeps up.
#include "SpareLine.hpp"
#include "KernelTestSupport.hpp"

#include <dcos/DsmAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/IdText.hpp>

#include <runtime/Text.hpp>
#include <shell/ShellCommand.hpp>

namespace target_test {

namespace {

using dcos::DsmPage;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::dsmAgent;
using dcos::taskAgent;
using dcos::timerAgent;
using runtime::textEquals;
using shell::CommandResult;

constexpr uint64_t kNsPerMs = 1'000'000;

// The page of write number @p counter: four words, each a different
// function of the counter, big-endian so a bus log reads them.
DsmPage pageOf(uint32_t counter)
{
    const uint32_t words[4] = {counter, ~counter, counter * 2654435761u, counter ^ 0x5A5A5A5Au};
    DsmPage page{};
    for (int w = 0; w < 4; ++w) {
        for (int b = 0; b < 4; ++b) {
            page.bytes[w * 4 + b] = static_cast<uint8_t>(words[w] >> (24 - 8 * b));
        }
    }
    return page;
}

// The counter of a whole page, or 0 for a torn one.
uint32_t counterOf(const DsmPage& page)
{
    uint32_t counter = 0;
    for (int b = 0; b < 4; ++b) {
        counter = (counter << 8) | page.bytes[b];
    }
    const DsmPage expected = pageOf(counter);
    for (size_t i = 0; i < dcos::kDsmPageSize; ++i) {
        if (expected.bytes[i] != page.bytes[i]) {
            return 0;
        }
    }
    return counter;
}

// The publishing task's orders, set before it is created.
const char* publishName = "";
dcos::Visibility publishVisibility = dcos::Visibility::Global;
volatile uint32_t publishPeriodMs = 10;
volatile uint32_t publishCount = 0;
volatile uint32_t published = 0;
volatile uint32_t publisherRaw = 0;
volatile bool publishDelete = false;
volatile bool publishGo = false;

void publisherEntry(uintptr_t)
{
    const Result<ObjectId> created = dsmAgent.Create(publishName, publishVisibility);
    if (!created.ok()) {
        publisherRaw = 0xFFFFFFFF;
        return;
    }
    publisherRaw = created.value().raw();
    while (!publishGo) {
        (void)taskAgent.SleepFor(kNsPerMs);
    }
    for (uint32_t counter = 1; counter <= publishCount; ++counter) {
        (void)dsmAgent.Write(created.value(), pageOf(counter));
        published = counter;
        (void)taskAgent.SleepFor(uint64_t{publishPeriodMs} * kNsPerMs);
    }
    // Done: the publisher stays, with its last page, until told to go.
    while (!publishDelete) {
        (void)taskAgent.SleepFor(10 * kNsPerMs);
    }
    (void)dsmAgent.Delete(created.value());
}

// An interrupt handler's Write: the routine on the spare line (5, vector
// 0x20 + the spare line) writes the page of isrCounter to the publishing task's publisher.
volatile uint32_t isrCounter = 0;
volatile Status isrWrite = Status::Ok;

void writingIsr(void*)
{
    isrWrite = dsmAgent.Write(ObjectId::fromRaw(publisherRaw), pageOf(isrCounter)).status();
}

// The subscriber's tally.
volatile uint32_t subscribeRaw = 0;
volatile Status openStatus = Status::Ok;
volatile uint32_t received = 0;
volatile uint32_t lastCounter = 0;
volatile uint32_t repeats = 0;
volatile uint32_t torn = 0;
volatile uint32_t gaps = 0;
volatile uint32_t deleted = 0;
volatile uint32_t waits = 0;
volatile uint32_t readTimeoutMs = 0;

void subscriberEntry(uintptr_t)
{
    const Result<ObjectId> subscription = dsmAgent.Open(ObjectId::fromRaw(subscribeRaw));
    openStatus = subscription.status();
    if (!subscription.ok()) {
        return;
    }
    uint32_t seen = dcos::kNoDsmData;
    for (;;) {
        DsmPage page;
        const uint64_t timeout = readTimeoutMs == 0 ? dcos::kWaitForever : uint64_t{readTimeoutMs} * kNsPerMs;
        const Result<uint32_t> read = dsmAgent.Read(subscription.value(), seen, page, timeout);
        if (read.status() == Status::Deleted) {
            deleted = deleted + 1;
            (void)dsmAgent.Close(subscription.value());
            return;
        }
        if (!read.ok()) {
            waits = waits + 1; // A time-out: nothing new came in time.
            continue;
        }
        seen = read.value();
        const uint32_t counter = counterOf(page);
        if (counter == 0) {
            torn = torn + 1;
            continue;
        }
        if (counter <= lastCounter) {
            repeats = repeats + 1;
            continue;
        }
        if (lastCounter != 0) {
            gaps = gaps + (counter - lastCounter - 1);
        }
        lastCounter = counter;
        received = received + 1;
    }
}

// Subscriptions the console holds (pubsub hold), to fill the remote publisher table.
constexpr size_t kMostHeld = 32;
ObjectId held[kMostHeld];
size_t heldCount = 0;

bool parseVisibility(const char* text, dcos::Visibility& visibility)
{
    if (textEquals(text, "local")) {
        visibility = dcos::Visibility::Local;
    } else if (textEquals(text, "regional")) {
        visibility = dcos::Visibility::Regional;
    } else if (textEquals(text, "global")) {
        visibility = dcos::Visibility::Global;
    } else {
        return false;
    }
    return true;
}

CommandResult pubsub(shell::Shell& shell, int argc, char** argv)
{
    if (argc < 2) {
        return CommandResult::UsageError;
    }
    const char* const verb = argv[1];
    ObjectId id;
    unsigned long priority = 0;
    if (textEquals(verb, "publish") && argc == 7) {
        // publish <name> <visibility> <priority> <period ms> <count>
        static char name[16];
        unsigned long period = 0, count = 0;
        if (runtime::textLength(argv[2]) >= sizeof name || !parseVisibility(argv[3], publishVisibility) ||
            !shell::Shell::parseUnsigned(argv[4], priority) || priority > dcos::kLowestPriority ||
            !shell::Shell::parseUnsigned(argv[5], period) || !shell::Shell::parseUnsigned(argv[6], count)) {
            return CommandResult::UsageError;
        }
        const size_t length = runtime::textLength(argv[2]);
        __builtin_memcpy(name, argv[2], length + 1);
        publishName = name;
        publishPeriodMs = static_cast<uint32_t>(period);
        publishCount = static_cast<uint32_t>(count);
        published = 0;
        publisherRaw = 0;
        publishDelete = false;
        publishGo = false;
        if (spawn("publisher", static_cast<uint8_t>(priority), publisherEntry).isNull()) {
            shell.print("error: cannot create the publishing task\r\n");
            return CommandResult::Failed;
        }
        for (int tries = 0; publisherRaw == 0 && tries < 100; ++tries) {
            (void)taskAgent.SleepFor(kNsPerMs);
        }
        shell.print("PPUB %s\r\n", dcos::internal::IdText(ObjectId::fromRaw(publisherRaw)).c_str());
        return CommandResult::Ok;
    }
    if (textEquals(verb, "published") && argc == 2) {
        shell.print("PCOUNT %lu\r\n", static_cast<unsigned long>(published));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "isr") && argc == 3) {
        // isr <counter>: the page of <counter> written by an interrupt handler.
        unsigned long counter = 0;
        if (!shell::Shell::parseUnsigned(argv[2], counter) || counter == 0) {
            return CommandResult::UsageError;
        }
        const Status installed = dcos::systemAgent.InstallISR(target_test::spareLine(), writingIsr, nullptr);
        if (installed != Status::Ok) {
            shell.print("error: InstallISR: %s\r\n", dcos::statusName(installed));
            return CommandResult::Failed;
        }
        isrCounter = static_cast<uint32_t>(counter);
        target_test::raiseSpareLine();
        (void)dcos::systemAgent.RemoveISR(target_test::spareLine());
        shell.print("RRES %s 0 0\r\n", dcos::statusName(isrWrite));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "go") && argc == 2) {
        publishGo = true;
        return CommandResult::Ok;
    }
    if (textEquals(verb, "delete") && argc == 2) {
        publishDelete = true;
        return CommandResult::Ok;
    }
    if (textEquals(verb, "subscribe") && (argc == 4 || argc == 5) && parseObjectId(argv[2], id) &&
        shell::Shell::parseUnsigned(argv[3], priority) && priority <= dcos::kLowestPriority) {
        // subscribe <publisher> <priority> [read time-out ms]
        unsigned long timeoutMs = 0;
        if (argc == 5 && !shell::Shell::parseUnsigned(argv[4], timeoutMs)) {
            return CommandResult::UsageError;
        }
        subscribeRaw = id.raw();
        readTimeoutMs = static_cast<uint32_t>(timeoutMs);
        openStatus = Status::Busy; // Until the task's Open returns.
        received = 0;
        lastCounter = 0;
        repeats = 0;
        torn = 0;
        gaps = 0;
        deleted = 0;
        waits = 0;
        const ObjectId task = spawn("subscriber", static_cast<uint8_t>(priority), subscriberEntry);
        if (task.isNull()) {
            shell.print("error: cannot create the subscribing task\r\n");
            return CommandResult::Failed;
        }
        shell.print("PTASK %s\r\n", dcos::internal::IdText(task).c_str());
        return CommandResult::Ok;
    }
    if (textEquals(verb, "tally") && argc == 2) {
        shell.print("PSUB %s %lu %lu %lu %lu %lu %lu %lu\r\n", dcos::statusName(openStatus),
                    static_cast<unsigned long>(received), static_cast<unsigned long>(lastCounter),
                    static_cast<unsigned long>(repeats), static_cast<unsigned long>(torn),
                    static_cast<unsigned long>(gaps), static_cast<unsigned long>(deleted),
                    static_cast<unsigned long>(waits));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "hold") && argc == 3 && parseObjectId(argv[2], id)) {
        // Open a subscription and keep it (the console task owns it) until release.
        if (heldCount == kMostHeld) {
            shell.print("error: %u subscriptions held already\r\n", unsigned(kMostHeld));
            return CommandResult::Failed;
        }
        const Result<ObjectId> opened = dsmAgent.Open(id);
        if (opened.ok()) {
            held[heldCount++] = opened.value();
        }
        shell.print("RRES %s %lu 0\r\n", dcos::statusName(opened.status()),
                    static_cast<unsigned long>(opened.ok() ? opened.value().raw() : 0));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "release") && argc == 2) {
        unsigned closed = 0;
        for (; heldCount > 0; --heldCount) {
            closed += dsmAgent.Close(held[heldCount - 1]) == Status::Ok ? 1 : 0;
        }
        shell.print("RRES ok %u 0\r\n", closed);
        return CommandResult::Ok;
    }
    if (textEquals(verb, "open") && argc == 3 && parseObjectId(argv[2], id)) {
        // Open and Close at once from the console: the refusals.
        const uint64_t start = timerAgent.Uptime();
        const Result<ObjectId> opened = dsmAgent.Open(id);
        const uint64_t us = (timerAgent.Uptime() - start) / 1000;
        if (opened.ok()) {
            (void)dsmAgent.Close(opened.value());
        }
        shell.print("RRES %s %lu %lu\r\n", dcos::statusName(opened.status()),
                    static_cast<unsigned long>(opened.ok() ? opened.value().raw() : 0),
                    static_cast<unsigned long>(us));
        return CommandResult::Ok;
    }
    return CommandResult::UsageError;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(
    pubsubCommand, "pubsub", "publishers and subscribers across boards, for the lab's tests (test image only)",
    "pubsub publish <name> local|regional|global <priority> <period ms> <count> | go | isr <counter> | published | delete | "
    "subscribe <publisher> <priority> [read time-out ms] | tally | open <publisher> | hold <publisher> | release",
    "  publish: a task creates the publisher; after go it writes <count> pages, one per period,\r\n"
    "  then keeps the publisher until delete; isr: an interrupt handler writes page <counter>\r\n"
    "  subscribe: a task opens the publisher (local or remote) and reads every new page\r\n"
    "  tally: PSUB <open status> <received> <last> <repeats> <torn> <gaps> <deleted> <time-outs>\r\n"
    "  open: Open and Close at once; prints RRES <status> <subscription> <microseconds>\r\n"
    "  hold: Open and keep the subscription; release: Close every one held",
    pubsub);

} // namespace target_test
