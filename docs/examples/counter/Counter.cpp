// A periodic task that publishes a counter, and a subscriber that checks it.
//
// The publisher writes the counter into a distributed shared memory page
// every 10 ms on an absolute schedule (a periodic alarm keeps its due
// times in nanoseconds, so the schedule does not drift however long a
// period's work takes). The subscriber reads every new page and checks
// that the counter advanced by exactly one per data identifier: the DSM
// agent gives each Write a data identifier one greater than the last, so
// a counter that advanced by more (a skipped value) or by less (a repeated
// or reordered value) is the publisher's fault, while a data identifier
// that advanced by more than one only means the subscriber missed pages.
//
// The application declares its two tasks, the publisher and the semaphore
// that guards the statistics; the loader creates them all before either
// task runs and stores their ids where the declarations point.
#include "Counter.hpp"

#include <bsp/Board.hpp>
#include <dcos/Application.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <runtime/Format.hpp>

namespace counter {

dcos::ObjectId publisherTask;
dcos::ObjectId statisticsLock;

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

ObjectId counterPublisher;

// The copies the console command reads; each task publishes its own
// running statistics here after every period (share below).
PublisherStatistics sharedPublisher;
SubscriberStatistics sharedSubscriber;

// A page travels between nodes once the network exists, so its fields are
// laid out byte by byte, least significant first, rather than copied from
// a structure whose layout is the compiler's: bytes 0-3 the counter,
// bytes 4-11 the publisher's uptime when it wrote the page.
dcos::DsmPage encodePage(uint32_t value, uint64_t uptimeNs)
{
    dcos::DsmPage page{};
    for (unsigned i = 0; i < 4; ++i) {
        page.bytes[i] = static_cast<uint8_t>(value >> (8 * i));
    }
    for (unsigned i = 0; i < 8; ++i) {
        page.bytes[4 + i] = static_cast<uint8_t>(uptimeNs >> (8 * i));
    }
    return page;
}

uint32_t decodeCounter(const dcos::DsmPage& page)
{
    uint32_t value = 0;
    for (unsigned i = 0; i < 4; ++i) {
        value |= static_cast<uint32_t>(page.bytes[i]) << (8 * i);
    }
    return value;
}

// How many Writes lie between two data identifiers. Identifiers grow by
// one per Write and skip kNoDsmData when they wrap past 2^32.
uint32_t writesBetween(uint32_t older, uint32_t newer)
{
    const uint32_t difference = newer - older;
    return newer < older ? difference - 1 : difference;
}

// Copies a task's running statistics to where the console reads them. A
// copy that cannot take the semaphore within a period is left for the next
// period: the task's own counts are never lost, only shown a period late.
template <class Statistics>
void share(Statistics& shared, const Statistics& own)
{
    if (dcos::semaphoreAgent.Acquire(statisticsLock, kPeriodNs) == Status::Ok) {
        shared = own;
        (void)dcos::semaphoreAgent.Release(statisticsLock); // Cannot fail: this task holds it.
    }
}

void publisherEntry(uintptr_t)
{
    const Result<ObjectId> timer = dcos::timerAgent.Create("counter.period", dcos::Visibility::Local);
    const Status started = timer.ok() ? dcos::timerAgent.SetPeriodicAlarm(timer.value(), kPeriodNs,
                                                                          dcos::AlarmNotification::event(kPeriodEvent))
                                      : timer.status();
    if (started != Status::Ok) {
        runtime::format(bsp::console(), "counter: the publisher cannot start its period: %s\r\n",
                        dcos::statusName(started));
        return;
    }
    PublisherStatistics own;
    uint32_t pendingFaults = 0;
    for (;;) {
        const Result<uint32_t> events = dcos::taskAgent.ReceiveEvent(kPeriodEvent | kSkipRequest | kRepeatRequest,
                                                                     dcos::EventWait::Any, dcos::kWaitForever);
        if (!events.ok()) {
            continue;
        }
        // A request waits for the next period, so the fault lands in the
        // regular schedule like any other value.
        pendingFaults |= events.value() & (kSkipRequest | kRepeatRequest);
        if ((events.value() & kPeriodEvent) == 0) {
            continue;
        }
        uint32_t fault = 0;
        uint32_t next = own.lastValue + 1;
        if ((pendingFaults & kSkipRequest) != 0) {
            fault = kSkipRequest;
            next = own.lastValue + 2;
        } else if ((pendingFaults & kRepeatRequest) != 0) {
            fault = kRepeatRequest;
            next = own.lastValue;
        }
        const uint64_t now = dcos::timerAgent.Uptime();
        if (dcos::dsmAgent.Write(counterPublisher, encodePage(next, now)).ok()) {
            ++own.published;
            own.lastValue = next;
            own.lastUptimeNs = now;
            if (fault != 0) {
                pendingFaults &= ~fault;
                ++own.faultsInjected;
            }
        } else {
            ++own.writeErrors;
        }
        share(sharedPublisher, own);
    }
}

void subscriberEntry(uintptr_t)
{
    const Result<ObjectId> subscription = dcos::dsmAgent.Open(counterPublisher);
    if (!subscription.ok()) {
        runtime::format(bsp::console(), "counter: the subscriber cannot open the publisher: %s\r\n",
                        dcos::statusName(subscription.status()));
        return;
    }
    // Before the first Write the publisher stands at counter 0 with data
    // identifier kNoDsmData, so the first page is checked like any other.
    SubscriberStatistics own;
    for (;;) {
        dcos::DsmPage page;
        const Result<uint32_t> read = dcos::dsmAgent.Read(subscription.value(), own.lastDataId, page, kStallNs);
        if (!read.ok()) {
            if (read.status() == Status::Timeout) {
                ++own.stalls;
            } else {
                // An error that persists (a deleted publisher) must not
                // turn this loop into a busy one.
                ++own.readErrors;
                // A sleep cut short by a signal only makes this wait shorter.
                (void)dcos::taskAgent.SleepFor(kPeriodNs);
            }
            share(sharedSubscriber, own);
            continue;
        }
        const uint32_t value = decodeCounter(page);
        const int64_t writes = writesBetween(own.lastDataId, read.value());
        const int64_t advance = static_cast<int32_t>(value - own.lastValue);
        own.missedPages += static_cast<uint32_t>(writes - 1);
        if (advance > writes) {
            ++own.skipped;
        } else if (advance < writes) {
            ++own.outOfOrder;
        }
        ++own.received;
        own.lastValue = value;
        own.lastDataId = read.value();
        share(sharedSubscriber, own);
    }
}

// The subscriber is less urgent than the publisher: a checker must not
// delay what it checks. At one page per 10 ms it still reads every page.
constexpr dcos::app::TaskDeclaration kTasks[] = {
    {.name = "publisher", .entry = publisherEntry, .priority = 10, .id = &publisherTask},
    {.name = "subscriber", .entry = subscriberEntry, .priority = 12},
};

constexpr dcos::app::PublisherDeclaration kPublishers[] = {
    {.name = "counter", .writer = "publisher", .id = &counterPublisher},
};

// Priority inheritance: the console, at a lower priority than both tasks,
// holds the semaphore while it copies the statistics.
constexpr dcos::app::SemaphoreDeclaration kSemaphores[] = {
    {.name = "counter.stats", .priorityInheritance = true, .id = &statisticsLock},
};

} // namespace

bool readStatistics(PublisherStatistics& publisher, SubscriberStatistics& subscriber)
{
    if (dcos::semaphoreAgent.Acquire(statisticsLock, 10 * kPeriodNs) != Status::Ok) {
        return false;
    }
    publisher = sharedPublisher;
    subscriber = sharedSubscriber;
    (void)dcos::semaphoreAgent.Release(statisticsLock); // Cannot fail: this task holds it.
    return true;
}

DCOS_APPLICATION(counterApplication, {
                                         .name = "counter",
                                         .tasks = kTasks,
                                         .semaphores = kSemaphores,
                                         .publishers = kPublishers,
                                     });

} // namespace counter
