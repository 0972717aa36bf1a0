#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/InterruptManager.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/Scheduler.hpp>

#include <arch_x86/Cpu.hpp>
#include <bsp/Board.hpp>

namespace dcos::internal {

namespace {

// The most urgent level each priority may set; level 1 (everything but the
// tick) until a super user says otherwise.
uint8_t legalLimits[kLowestPriority + 1] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1,
                                            1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
bool installedByAgent[bsp::interruptLineCount];

} // namespace

Status InterruptManager::installIsr(unsigned line, void (*handler)(void* context), void* context)
{
    if (!currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    if (line >= bsp::interruptLineCount || handler == nullptr) {
        return Status::InvalidArgument;
    }
    const Status status = bsp::attachInterrupt(line, handler, context);
    if (status == Status::Ok) {
        installedByAgent[line] = true;
    }
    return status;
}

Status InterruptManager::removeIsr(unsigned line)
{
    if (!currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    if (line >= bsp::interruptLineCount || !installedByAgent[line]) {
        // The kernel's own handlers (tick, console) cannot be removed this way.
        return Status::InvalidArgument;
    }
    installedByAgent[line] = false;
    return bsp::detachInterrupt(line);
}

Result<uint8_t> InterruptManager::setInterruptLevel(uint8_t level)
{
    if (level == 0 || (level >= bsp::interruptLevelCount && level != kNoLevel)) {
        return Status::InvalidArgument; // Level 0, the tick, cannot be masked.
    }
    if (inInterruptContext()) {
        return Status::InInterrupt;
    }
    arch_x86::InterruptGuard guard;
    Task& task = Scheduler::current();
    const uint8_t limit = legalLimits[task.priority];
    const uint8_t granted = level < limit ? limit : level;
    task.interruptLevel = granted;
    task.refreshSwitchWork();
    applyTaskLevel(granted);
    return granted;
}

Status InterruptManager::setLegalLimit(uint8_t priority, uint8_t level)
{
    if (!currentTaskIsSuperUser()) {
        return Status::NotPermitted;
    }
    if (priority > kLowestPriority || level == 0 || (level >= bsp::interruptLevelCount && level != kNoLevel)) {
        return Status::InvalidArgument;
    }
    legalLimits[priority] = level;
    return Status::Ok;
}

uint8_t InterruptManager::legalLimit(uint8_t priority)
{
    return priority <= kLowestPriority ? legalLimits[priority] : kNoLevel;
}

void InterruptManager::applyTaskLevel(uint8_t level) { bsp::setTaskInterruptLevel(level); }

} // namespace dcos::internal

namespace dcos {

// The interrupt half of the system agent's interface object; the device
// half is in DeviceManager.cpp.

Status SystemAgent::InstallISR(unsigned line, InterruptServiceRoutine isr, void* context)
{
    return internal::InterruptManager::installIsr(line, isr, context);
}

Status SystemAgent::RemoveISR(unsigned line) { return internal::InterruptManager::removeIsr(line); }

Result<uint8_t> SystemAgent::SetInterruptLevel(uint8_t level)
{
    return internal::InterruptManager::setInterruptLevel(level);
}

Status SystemAgent::SetInterruptLevel(uint8_t priority, uint8_t legalLimit)
{
    return internal::InterruptManager::setLegalLimit(priority, legalLimit);
}

} // namespace dcos
