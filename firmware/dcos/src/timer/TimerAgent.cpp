// The timer agent's interface object (seed 7.5).
#include <dcos/TimerAgent.hpp>
#include <dcos/GregorianCalendar.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/TimerManager.hpp>
#include <dcos/internal/ConfigurationService.hpp>

namespace dcos {

using internal::TimerManager;

Status TimerAgent::SetSystemClock(const DateTime& time)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    return TimerManager::setSystemClock(time);
}

uint64_t TimerAgent::Uptime() { return TimerManager::preciseUptimeNs(); }

DCOS_CONFIGURATION_SERVICE Result<ObjectId> TimerAgent::Create(const char* name, Visibility visibility)
{
    return TimerManager::createTimer(internal::currentTaskId(), name, visibility);
}

DCOS_CONFIGURATION_SERVICE Status TimerAgent::Delete(ObjectId timer) { return TimerManager::deleteTimer(timer, internal::currentTaskId()); }

// Each alarm primitive given another node's timer sets it there, for the
// calling task, which must own it (docs/protocols/remote-transactions.md,
// "Timers").
Status TimerAgent::SetWatchDogAlarm(ObjectId timer, uint64_t intervalNs, AlarmNotification notification)
{
    const Status local = TimerManager::setWatchDogAlarm(timer, internal::currentTaskId(), intervalNs, notification);
    return internal::orRemoteAlarm(local, timer, internal::RemoteAlarmKind::WatchDog, notification, intervalNs);
}

Status TimerAgent::SetDayClockAlarm(ObjectId timer, const DateTime& time, AlarmNotification notification)
{
    const Status local = TimerManager::setDayClockAlarm(timer, internal::currentTaskId(), time, notification);
    if (local != Status::Remote) [[likely]] {
        return local;
    }
    // As the time of day in nanoseconds since 1970, which the timer's node
    // turns back into its calendar.
    const Result<uint64_t> ns = GregorianCalendar::toNanoseconds(time);
    return ns.ok() ? internal::orRemoteAlarm(local, timer, internal::RemoteAlarmKind::DayClock, notification, ns.value())
                   : ns.status();
}

Status TimerAgent::SetPeriodicAlarm(ObjectId timer, uint64_t periodNs, AlarmNotification notification)
{
    const Status local = TimerManager::setPeriodicAlarm(timer, internal::currentTaskId(), periodNs, notification);
    return internal::orRemoteAlarm(local, timer, internal::RemoteAlarmKind::Periodic, notification, periodNs);
}

Status TimerAgent::CancelAlarm(ObjectId timer)
{
    const ObjectId self = internal::currentTaskId();
    return internal::orRemote(TimerManager::cancelAlarm(timer, self), internal::RemoteService::TimerCancelAlarm, timer,
                              self.raw());
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> TimerAgent::NameToObject(const char* name)
{
    return internal::orRemoteName(TimerManager::timerNameToObject(name), ObjectType::Timer, name);
}

DCOS_CONFIGURATION_SERVICE Status TimerAgent::XferOwnership(ObjectId timer, ObjectId newOwner)
{
    return TimerManager::xferOwnership(timer, internal::currentTaskId(), newOwner);
}

DCOS_CONFIGURATION_SERVICE Status TimerAgent::AddObjects(size_t count)
{
    if (!internal::currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    return TimerManager::addTimerObjects(count);
}

} // namespace dcos
