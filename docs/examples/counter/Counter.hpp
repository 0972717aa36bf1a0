// What the counter application's tasks share with its console command.
//
// The publisher task writes an incrementing counter into a distributed
// shared memory publisher every period; the subscriber task reads every
// new page and checks that the counter advanced by exactly one per data
// identifier. Both keep statistics here, which the `counter` command
// prints. The statistics are several words, so they are read and written
// only while holding the statistics semaphore: a reader then never sees
// half of an update.
#pragma once

#include <dcos/ObjectId.hpp>

#include <stdint.h>

namespace counter {

/// The publisher's period. The schedule is absolute (a periodic alarm), so
/// value n is published n periods after the first, however long each
/// period's work takes.
constexpr uint64_t kPeriodNs = 10000000;

/// Event flags of the publisher task. The alarm posts kPeriodEvent; the
/// console command posts a fault request, which the next period applies.
constexpr uint32_t kPeriodEvent = 1u << 0;
constexpr uint32_t kSkipRequest = 1u << 1;   ///< Publish value + 2 once: one value is never published.
constexpr uint32_t kRepeatRequest = 1u << 2; ///< Publish the same value again once.

/// What the publisher has done.
struct PublisherStatistics {
    uint32_t published = 0;      ///< Successful Writes.
    uint32_t lastValue = 0;      ///< The counter in the last page written.
    uint64_t lastUptimeNs = 0;   ///< When the last page was written (TimerAgent::Uptime).
    uint32_t writeErrors = 0;    ///< Writes the DSM agent refused.
    uint32_t faultsInjected = 0; ///< Skips and repeats done on request.
};

/// What the subscriber has found.
struct SubscriberStatistics {
    uint32_t received = 0;   ///< Pages read.
    uint32_t lastValue = 0;  ///< The counter in the last page read.
    uint32_t lastDataId = 0; ///< The data identifier of the last page read.
    uint32_t skipped = 0;    ///< Pages whose counter advanced more than their data identifier.
    uint32_t outOfOrder = 0; ///< Pages whose counter advanced less (repeated or went back).
    uint32_t missedPages = 0; ///< Writes overwritten before the subscriber read them (not an error of the counter).
    uint32_t readErrors = 0; ///< Reads that failed other than by timing out.
    uint32_t stalls = 0;     ///< Reads that waited kStallNs without a new page.
};

/// A subscriber that waits this long for a page reports a stall: the
/// publisher should have written five times meanwhile.
constexpr uint64_t kStallNs = 5 * kPeriodNs;

// Filled in by the application loader before any task runs (Counter.cpp).
extern dcos::ObjectId publisherTask;
extern dcos::ObjectId statisticsLock;

/// Copies of the statistics, taken under the statistics semaphore. Return
/// false when the semaphore could not be taken (the copies are then stale).
bool readStatistics(PublisherStatistics& publisher, SubscriberStatistics& subscriber);

} // namespace counter
