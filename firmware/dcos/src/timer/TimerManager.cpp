#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/GregorianCalendar.hpp>
#include <dcos/internal/CalendarCache.hpp>
#include <dcos/internal/DayClockWheel.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/ObjectTable.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/ResourceRecovery.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimeWheel.hpp>
#include <dcos/internal/TimerManager.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <arch_x86/Cpu.hpp>
#include <boot/Panic.hpp>
#include <bsp/Board.hpp>

namespace dcos::internal {

namespace {

enum class AlarmKind : uint8_t { None, WatchDog, DayClock, Periodic };

// A software timer object (seed 7.5).
struct TimerObject {
    TimerObject() : entry(TimeoutEntry::Kind::Alarm, this) {}
    ObjectId id;
    AlarmKind kind = AlarmKind::None;
    AlarmNotification notification;
    uint64_t periodNs = 0;
    uint64_t nextDueNs = 0; ///< Uptime of a periodic alarm's next expiry.
    TimeoutEntry entry;     ///< A day-clock alarm's time of day is entry.timeOfDayNs.
};

// Time-outs keyed by uptime tick: watch-dog and periodic alarms, waits,
// deadlines, and day-clock entries due at this tick or the next.
TimeWheel<TimeoutEntry, kTimeWheelSlots> wheel;
// Day-clock alarms and SleepTill, keyed by time of day, so that setting the
// clock touches none of them (DayClockWheel.hpp).
DayClockWheel<TimeoutEntry, kTimeWheelSlots> dayClock;
volatile uint64_t tickCount = 0;
volatile uint64_t incrementNs = 0; // Nanoseconds ticked since the tick started.
uint64_t baseNs = 0;               // Time of day, in ns since 1970, when the tick started.
uint64_t lastReportedUptimeNs = 0; // The latest precise uptime handed out (see preciseUptime).
uint32_t clockGeneration = 0;      // Counts SetSystemClock calls, so a conversion knows its base is still in force.
CalendarCache calendar;            // GetSystemClock's calendar of the current second.

ObjectTable<TimerObject*, kTimerCapacity, TaskOwnerKeys> timerTable(ObjectType::Timer, 0);
TimerObject timers[kTimerCapacity];

size_t timerSlotOf(ObjectId id) { return timerTable.slotNumber(id); }

// The first tick whose time (uptime) is at or after ns.
// The first tick whose start is at or after ns of uptime: a time-out armed
// for it fires no earlier than ns, and less than a tick later. Rounded up
// without forming ns + period, which would wrap for ns near 2^64.
uint64_t firstTickAtOrAfter(uint64_t ns)
{
    const uint64_t period = TimerManager::tickPeriodNs();
    const uint64_t ticks = ns / period;
    return ns % period != 0 ? ticks + 1 : ticks;
}

// a + b, held at the largest value instead of wrapping: a time-out within
// a tick of 2^64 ns is a very long wait, never one that expires at once.
uint64_t saturatingAdd(uint64_t a, uint64_t b) { return b > UINT64_MAX - a ? UINT64_MAX : a + b; }

void notifyOwner(TimerObject& timer)
{
    const Result<ObjectId> owner = timerTable.ownerOf(timer.id);
    if (!owner.ok()) {
        return;
    }
    if (owner.value().node() != timerTable.node()) [[unlikely]] {
        // An owner on another node: the remote agent's notifier tells it
        // from a task (docs/protocols/remote-transactions.md, "Timers").
        queueRemoteAlarm(timer.id, owner.value(), timer.notification);
        return;
    }
    const Result<Task*> task = TaskManager::resolve(owner.value());
    if (!task.ok()) {
        return;
    }
    if (timer.notification.kind == AlarmNotification::Kind::Event) {
        TaskManager::postEvent(*task.value(), timer.notification.value);
    } else {
        TaskManager::sendSignal(*task.value(), timer.notification.value);
    }
}

// Takes an entry off whichever list holds it, the tick wheel's or the
// day-clock wheel's (TimeWheel::cancel only unlinks); nothing if it is not
// armed.
[[gnu::always_inline]] inline void disarm(TimeoutEntry& entry) { (void)wheel.cancel(entry); }

void expire(TimeoutEntry& entry)
{
    switch (entry.kind) {
    case TimeoutEntry::Kind::TaskWake:
        TaskManager::wake(*static_cast<Task*>(entry.owner), Status::Timeout);
        break;
    case TimeoutEntry::Kind::DeadlineMiss: {
        Task& task = *static_cast<Task*>(entry.owner);
        if (task.inDeadlineScope) {
            TaskManager::raiseException(task, ExceptionInfo{ExceptionClass::Timing, 0xFF, 0, 0, nullptr});
        }
        break;
    }
    case TimeoutEntry::Kind::Alarm: {
        TimerObject& timer = *static_cast<TimerObject*>(entry.owner);
        if (timer.kind == AlarmKind::Periodic) {
            // Keep the schedule in nanoseconds and go off at the first tick
            // at or after each due time: never early, and no drift although
            // the tick is not a whole number of nanoseconds of the period.
            timer.nextDueNs += timer.periodNs;
            // Cannot fail: the wheel has just taken the entry out.
            (void)wheel.insert(timer.entry, firstTickAtOrAfter(timer.nextDueNs));
        } else {
            timer.kind = AlarmKind::None;
        }
        notifyOwner(timer);
        break;
    }
    }
}

// Nanoseconds since the tick started, refined within the tick by the
// board. Interrupts disabled. The tick timer's counter and its interrupt
// request are read one after the other, and an emulated or real 8254 may
// reload the counter a moment before the request shows: the sum could then
// step back by up to a tick. Uptime must never run backwards (intervals are
// computed by subtraction), so it holds at the last value instead.
[[gnu::always_inline]] inline uint64_t preciseUptime()
{
    const uint64_t now = incrementNs + bsp::nanosecondsIntoTick();
    const uint64_t last = lastReportedUptimeNs;
    if (now < last) [[unlikely]] {
        return last;
    }
    lastReportedUptimeNs = now;
    return now;
}

Result<TimerObject*> resolveOwnedTimer(ObjectId id, ObjectId caller)
{
    const Result<TimerObject**> entry = timerTable.resolve(id);
    if (!entry.ok()) {
        return entry.status();
    }
    const Status owner = timerTable.checkOwnerOrPrivileged(id, caller, currentTaskIsSuperUser());
    if (owner != Status::Ok) {
        return owner;
    }
    return *entry.value();
}

// What every Set...Alarm does first: the timer's previous alarm, if any, is
// cancelled, and the new one's kind and notification are recorded; the
// caller then schedules it. Forced inline: as a call it costs every alarm
// primitive one to four instructions (make bench).
[[gnu::always_inline]] inline void replaceAlarm(TimerObject& timer, AlarmKind kind, const AlarmNotification& n)
{
    disarm(timer.entry);
    timer.kind = kind;
    timer.notification = n;
}

Status validNotification(const AlarmNotification& n)
{
    if (n.kind == AlarmNotification::Kind::Signal) {
        return n.value < 32 ? Status::Ok : Status::InvalidArgument;
    }
    return n.value != 0 ? Status::Ok : Status::InvalidArgument;
}

unsigned recoverTimers(ObjectId deadTask)
{
    arch_x86::InterruptGuard guard;
    return static_cast<unsigned>(timerTable.forEachOwnedBy(deadTask, [](ObjectId id, TimerObject*& timer) {
        disarm(timer->entry);
        timer->kind = AlarmKind::None;
        // Cannot fail: the walk hands out only live ids of this table.
        (void)timerTable.Delete(id);
    }));
}

} // namespace

uint64_t TimerManager::tickPeriodNs_ = 1000000;

void TimerManager::initialise(uint64_t tickPeriodNs)
{
    tickPeriodNs_ = tickPeriodNs;
    dayClock.setPeriod(tickPeriodNs);
    if (timerTable.setNode(bsp::nodeId()) != Status::Ok || timerTable.AddObjects(kTimersActiveAtBoot) != Status::Ok) {
        dcosPanic("cannot set up the timer table (node %u, %lu timers)", static_cast<unsigned>(bsp::nodeId()),
                  static_cast<unsigned long>(kTimersActiveAtBoot));
    }
}

void TimerManager::onTick()
{
    tickCount = tickCount + 1;
    incrementNs = incrementNs + tickPeriodNs_;
    // Day-clock time-outs first (DayClockWheel.hpp says why).
    dayClock.advance(tickCount, incrementNs, expire);
    wheel.advance(tickCount, expire);
    Scheduler::onTick();
}

uint64_t TimerManager::ticks()
{
    arch_x86::InterruptGuard guard;
    return tickCount;
}

uint64_t TimerManager::uptimeNs()
{
    arch_x86::InterruptGuard guard;
    return incrementNs;
}

uint64_t TimerManager::preciseUptimeNs()
{
    arch_x86::InterruptGuard guard;
    return preciseUptime();
}

uint64_t TimerManager::tickAfter(uint64_t ns)
{
    // Measured from the precise time now, not from the start of the current
    // tick: counting whole ticks from the tick's start needs one tick more
    // for the part already gone, and a tick of the 8254 (999,847 ns at
    // 1 kHz) rounds 1 ms up to two, so waits ran up to two ticks long.
    return firstTickAtOrAfter(saturatingAdd(preciseUptimeNs(), ns));
}

uint64_t TimerManager::tickAtUptime(uint64_t uptimeNs) { return firstTickAtOrAfter(uptimeNs); }

void TimerManager::arm(TimeoutEntry& entry, uint64_t dueTick)
{
    arch_x86::InterruptGuard guard;
    // Re-arms: the insert after disarm cannot find the entry armed.
    disarm(entry);
    (void)wheel.insert(entry, dueTick);
}

void TimerManager::armAtTimeOfDay(TimeoutEntry& entry, uint64_t timeOfDayNs)
{
    arch_x86::InterruptGuard guard;
    disarm(entry);
    dayClock.arm(entry, timeOfDayNs, tickCount);
}

void TimerManager::cancelArmed(TimeoutEntry& entry)
{
    arch_x86::InterruptGuard guard;
    disarm(entry); // Not armed: it has expired already, which is as good.
}

uint64_t TimerManager::timeOfDayNs()
{
    arch_x86::InterruptGuard guard;
    return baseNs + preciseUptime();
}

namespace {

// GetSystemClock's fast path and slow path leave the critical section at
// different points, so it uses InterruptGuard's two halves,
// arch_x86::saveFlagsAndDisableInterrupts() and restoreFlags().
using arch_x86::restoreFlags;

// GetSystemClock's slow path: a read that is not within the second of the
// cached calendar. Interrupts are disabled on entry and restored from
// savedFlags on return. A read in the next second steps the cache; the full
// conversion (about 800 instructions) runs with interrupts enabled and its
// result is cached only if the clock was not set meanwhile, since the cache
// holds uptimes and is right only for the base it was computed with.
[[gnu::noinline]] Result<DateTime> convertSlowly(uint64_t uptime, uint32_t savedFlags)
{
    DateTime time;
    if (calendar.advance(uptime) && calendar.read(uptime, time)) {
        restoreFlags(savedFlags);
        return time;
    }
    const uint64_t base = baseNs;
    const uint32_t generation = clockGeneration;
    restoreFlags(savedFlags);
    time = GregorianCalendar::fromNanoseconds(base + uptime);
    arch_x86::InterruptGuard guard;
    if (generation == clockGeneration) {
        calendar.refill(uptime, time);
    }
    return time;
}

// The first nanosecond past TimerAgent::kLastClockYear: 1 January 2400,
// 157,054 days after 1 January 1970 (430 years, 104 of them leap years).
constexpr uint64_t lastClockNs = uint64_t{157'054} * 86'400 * 1'000'000'000 - 1;
static_assert(TimerAgent::kLastClockYear == 2399);

// Changes the base (seed 7.5), with interrupts disabled; @p elapsed is the
// uptime now. Day-clock alarms and SleepTill are keyed by time of day
// (DayClockWheel), so none of them is touched: the time with interrupts
// held off is the same for any number of timers and tasks.
void setBase(uint64_t base, uint64_t elapsed)
{
    baseNs = base;
    dayClock.setBase(baseNs, tickCount);
    ++clockGeneration;
    calendar.invalidate(elapsed);
}

// GetSystemClock, inlined into both of its entry points.
[[gnu::always_inline]] inline Result<DateTime> readSystemClock()
{
    // The common case, a read within the second of the previous one, only
    // subtracts and copies (CalendarCache), with interrupts held off for a
    // few instructions.
    const uint32_t savedFlags = arch_x86::saveFlagsAndDisableInterrupts();
    const uint64_t uptime = preciseUptime();
    Result<DateTime> result = calendar.answer();
    uint32_t nanosecond;
    if (calendar.contains(uptime, nanosecond)) {
        CalendarCache::patchNanosecond(result, nanosecond);
        restoreFlags(savedFlags);
        return result;
    }
    result = convertSlowly(uptime, savedFlags);
    return result;
}

} // namespace

Result<DateTime> TimerManager::getSystemClock() { return readSystemClock(); }

Status TimerManager::setSystemClock(const DateTime& time)
{
    if (time.year > TimerAgent::kLastClockYear) {
        return Status::InvalidArgument; // The clock could not carry it for long.
    }
    const Result<uint64_t> target = GregorianCalendar::toNanoseconds(time);
    if (!target.ok()) {
        return target.status();
    }
    arch_x86::InterruptGuard guard;
    const uint64_t elapsed = preciseUptime();
    if (target.value() < elapsed) {
        return Status::InvalidArgument; // Before the node was started.
    }
    setBase(target.value() - elapsed, elapsed);
    return Status::Ok;
}

uint64_t TimerManager::timeOfDayAtUptime(uint64_t uptimeNs)
{
    arch_x86::InterruptGuard guard;
    return baseNs + uptimeNs;
}

Status TimerManager::setTimeOfDayAt(uint64_t timeOfDayNs, uint64_t uptimeNs)
{
    if (timeOfDayNs < uptimeNs || timeOfDayNs > lastClockNs) {
        return Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    setBase(timeOfDayNs - uptimeNs, preciseUptime());
    return Status::Ok;
}

Result<uint64_t> TimerManager::nanosecondsUntil(const DateTime& time)
{
    const Result<uint64_t> target = GregorianCalendar::toNanoseconds(time);
    if (!target.ok()) {
        return target.status();
    }
    const uint64_t now = timeOfDayNs();
    return target.value() > now ? target.value() - now : 0;
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> TimerManager::createTimer(ObjectId owner, const char* name, Visibility visibility)
{
    arch_x86::InterruptGuard guard;
    const Result<ObjectId> id = timerTable.Create(owner, name, visibility);
    if (!id.ok()) {
        return id.status();
    }
    TimerObject& timer = timers[timerSlotOf(id.value())];
    timer.id = id.value();
    timer.kind = AlarmKind::None;
    *timerTable.resolve(id.value()).value() = &timer;
    return id.value();
}

DCOS_CONFIGURATION_SERVICE Status TimerManager::deleteTimer(ObjectId id, ObjectId caller)
{
    arch_x86::InterruptGuard guard;
    const Result<TimerObject*> timer = resolveOwnedTimer(id, caller);
    if (!timer.ok()) {
        return timer.status();
    }
    disarm(timer.value()->entry);
    timer.value()->kind = AlarmKind::None;
    return timerTable.Delete(id);
}

Status TimerManager::setWatchDogAlarm(ObjectId id, ObjectId caller, uint64_t intervalNs, AlarmNotification n)
{
    if (validNotification(n) != Status::Ok) {
        return Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    const Result<TimerObject*> timer = resolveOwnedTimer(id, caller);
    if (!timer.ok()) {
        return timer.status();
    }
    TimerObject& t = *timer.value();
    replaceAlarm(t, AlarmKind::WatchDog, n);
    (void)wheel.insert(t.entry, tickAfter(intervalNs)); // Cannot fail: replaceAlarm disarmed it.
    return Status::Ok;
}

Status TimerManager::setDayClockAlarm(ObjectId id, ObjectId caller, const DateTime& time, AlarmNotification n)
{
    if (validNotification(n) != Status::Ok) {
        return Status::InvalidArgument;
    }
    const Result<uint64_t> target = GregorianCalendar::toNanoseconds(time);
    if (!target.ok()) {
        return target.status();
    }
    arch_x86::InterruptGuard guard;
    const Result<TimerObject*> timer = resolveOwnedTimer(id, caller);
    if (!timer.ok()) {
        return timer.status();
    }
    TimerObject& t = *timer.value();
    replaceAlarm(t, AlarmKind::DayClock, n);
    dayClock.arm(t.entry, target.value(), tickCount); // replaceAlarm disarmed it.
    return Status::Ok;
}

Status TimerManager::setPeriodicAlarm(ObjectId id, ObjectId caller, uint64_t periodNs, AlarmNotification n)
{
    if (validNotification(n) != Status::Ok || periodNs < tickPeriodNs_) {
        return Status::InvalidArgument; // A period shorter than a tick cannot be kept.
    }
    arch_x86::InterruptGuard guard;
    const Result<TimerObject*> timer = resolveOwnedTimer(id, caller);
    if (!timer.ok()) {
        return timer.status();
    }
    TimerObject& t = *timer.value();
    replaceAlarm(t, AlarmKind::Periodic, n);
    t.periodNs = periodNs;
    // The schedule starts from the current tick's time, the base of every
    // interval measured in ticks.
    t.nextDueNs = incrementNs + periodNs;
    (void)wheel.insert(t.entry, firstTickAtOrAfter(t.nextDueNs)); // Cannot fail: replaceAlarm disarmed it.
    return Status::Ok;
}

Status TimerManager::cancelAlarm(ObjectId id, ObjectId caller)
{
    arch_x86::InterruptGuard guard;
    const Result<TimerObject*> timer = resolveOwnedTimer(id, caller);
    if (!timer.ok()) {
        return timer.status();
    }
    if (timer.value()->kind == AlarmKind::None) {
        return Status::InvalidArgument; // No alarm is set.
    }
    disarm(timer.value()->entry); // An alarm still set is armed.
    timer.value()->kind = AlarmKind::None;
    return Status::Ok;
}

Result<ObjectId> TimerManager::timerNameToObject(const char* name, Visibility askingScope)
{
    arch_x86::InterruptGuard guard;
    return timerTable.NameToObject(name, askingScope);
}

DCOS_CONFIGURATION_SERVICE Status TimerManager::xferOwnership(ObjectId id, ObjectId caller, ObjectId newOwner)
{
    // A timer may be owned by a task of another node, which sets its alarms
    // over the network and is notified so (seed 6.4, 7.5): that task is
    // asked whether it exists, once the caller is known to be allowed to give it.
    if (!newOwner.isNull() && newOwner.type() == ObjectType::Task && newOwner.node() != timerTable.node()) {
        {
            arch_x86::InterruptGuard guard;
            const Result<TimerObject*> timer = resolveOwnedTimer(id, caller);
            if (!timer.ok()) {
                return timer.status();
            }
        }
        const Result<TaskState> state = TaskAgent::GetState(newOwner);
        if (!state.ok()) {
            return state.status();
        }
        if (state.value() == TaskState::NonExistent || state.value() == TaskState::Terminating) {
            return Status::InvalidId;
        }
    } else {
        const Status newOwnerStatus = TaskManager::checkNewOwner(newOwner);
        if (newOwnerStatus != Status::Ok) {
            return newOwnerStatus;
        }
    }
    arch_x86::InterruptGuard guard;
    const Result<TimerObject*> timer = resolveOwnedTimer(id, caller);
    if (!timer.ok()) {
        return timer.status();
    }
    const Result<ObjectId> owner = timerTable.ownerOf(id);
    return timerTable.XferOwnership(id, owner.value(), newOwner);
}

Result<ObjectId> TimerManager::timerOwner(ObjectId id)
{
    arch_x86::InterruptGuard guard;
    return timerTable.ownerOf(id);
}

void TimerManager::dropTimerOfLostOwner(ObjectId id, ObjectId owner)
{
    arch_x86::InterruptGuard guard;
    const Result<ObjectId> current = timerTable.ownerOf(id);
    const Result<TimerObject**> entry = timerTable.resolve(id);
    if (!current.ok() || current.value() != owner || !entry.ok()) {
        return; // Deleted or given to another owner meanwhile.
    }
    TimerObject& timer = **entry.value();
    disarm(timer.entry);
    timer.kind = AlarmKind::None;
    (void)timerTable.Delete(id);
}

size_t TimerManager::dropTimersOwnedOnNode(uint16_t node)
{
    size_t dropped = 0;
    for (size_t slot = 0; slot < timerTable.activeCount(); ++slot) {
        ObjectId id;
        ObjectId owner;
        {
            arch_x86::InterruptGuard guard;
            id = timers[slot].id;
            // A free or deleted slot's id (null, or stale) has no owner.
            const Result<ObjectId> current = timerTable.ownerOf(id);
            if (!current.ok() || current.value().isNull() || current.value().node() != node) {
                continue;
            }
            owner = current.value();
        }
        dropTimerOfLostOwner(id, owner);
        ++dropped;
    }
    return dropped;
}

Status TimerManager::addTimerObjects(size_t count)
{
    arch_x86::InterruptGuard guard;
    return timerTable.AddObjects(count);
}

size_t TimerManager::timerCount() { return timerTable.usedCount(); }

DCOS_RESOURCE_RECOVERY(timerRecovery, "timer", recoverTimers);

ObjectTableView timerTableView()
{
    return timerTable.view();
}

} // namespace dcos::internal

namespace dcos {

// Defined here rather than with the other interface functions in
// TimerAgent.cpp so that the clock read is inlined into it: the call and
// frame of a forwarding function would take a fifth of the primitive's
// instruction budget.
Result<DateTime> TimerAgent::GetSystemClock() { return internal::readSystemClock(); }

} // namespace dcos
