// The timer agent's interface object (seed 7.5).
#include <dcos/TimerAgent.hpp>
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

Status TimerAgent::SetWatchDogAlarm(ObjectId timer, uint64_t intervalNs, AlarmNotification notification)
{
    return TimerManager::setWatchDogAlarm(timer, internal::currentTaskId(), intervalNs, notification);
}

Status TimerAgent::SetDayClockAlarm(ObjectId timer, const DateTime& time, AlarmNotification notification)
{
    return TimerManager::setDayClockAlarm(timer, internal::currentTaskId(), time, notification);
}

Status TimerAgent::SetPeriodicAlarm(ObjectId timer, uint64_t periodNs, AlarmNotification notification)
{
    return TimerManager::setPeriodicAlarm(timer, internal::currentTaskId(), periodNs, notification);
}

Status TimerAgent::CancelAlarm(ObjectId timer) { return TimerManager::cancelAlarm(timer, internal::currentTaskId()); }

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
