#include <bsp/LocalApic.hpp>

namespace bsp {

uint8_t LocalApic::id() const { return static_cast<uint8_t>(registers_.read32(kId) >> kIdShift); }

uint8_t LocalApic::version() const { return static_cast<uint8_t>(registers_.read32(kVersion) & kVersionMask); }

uint8_t LocalApic::maximumLvtEntry() const
{
    return static_cast<uint8_t>((registers_.read32(kVersion) >> kMaximumLvtShift) & kVersionMask);
}

bool LocalApic::enable(uint8_t spuriousVector)
{
    // The low four bits cannot be anything but ones on this APIC, so a
    // vector without them would be delivered somewhere else than asked.
    if ((spuriousVector & kSpuriousLowBits) != kSpuriousLowBits || spuriousVector < kLowestVector) {
        return false;
    }
    // Enable first: while the APIC is software-disabled every LVT mask bit
    // is forced to 1 and cannot be cleared (11.4.7.2), so LINT1 could not
    // be opened for NMIs before this write.
    registers_.write32(kSpuriousVector, kSoftwareEnable | spuriousVector);
    registers_.write32(kDestinationFormat, kFlatModel);
    registers_.write32(kLogicalDestination, (1u << (id() % kFlatLogicalIds)) << kLogicalIdShift);
    registers_.write32(kTaskPriority, 0);
    // Interrupts come through the I/O APIC; the 8259's INTR wire, which
    // reaches LINT0 in virtual-wire mode, stays shut.
    registers_.write32(kLvtLint0, kLvtMask | kDeliveryExtInt);
    registers_.write32(kLvtLint1, kDeliveryNmi);
    registers_.write32(kLvtError, kLvtMask);
    registers_.write32(kLvtTimer, kLvtMask);
    return true;
}

bool LocalApic::startTimer(uint8_t vector, uint32_t initialCount, TimerDivide divide, uint32_t mode) const
{
    // A count of 0 stops the timer instead of starting it (11.5.4).
    if (vector < kLowestVector || initialCount == 0) {
        return false;
    }
    registers_.write32(kTimerDivide, divideConfiguration(divide));
    registers_.write32(kLvtTimer, mode | vector);
    // Writing the initial count starts the count down, so it goes last.
    registers_.write32(kTimerInitialCount, initialCount);
    return true;
}

bool LocalApic::startPeriodic(uint8_t vector, uint32_t initialCount, TimerDivide divide) const
{
    return startTimer(vector, initialCount, divide, kTimerPeriodic);
}

bool LocalApic::startOneShot(uint8_t vector, uint32_t initialCount, TimerDivide divide) const
{
    return startTimer(vector, initialCount, divide, 0);
}

void LocalApic::stopTimer() const
{
    registers_.write32(kLvtTimer, kLvtMask);
    registers_.write32(kTimerInitialCount, 0);
}

void LocalApic::setTaskPriority(uint8_t priority) const { registers_.write32(kTaskPriority, priority); }

bool LocalApic::sendCommand(uint8_t destination, uint32_t low, uint32_t spins) const
{
    // The write of the low word sends the message, so the destination
    // must already be in place.
    registers_.write32(kCommandHigh, static_cast<uint32_t>(destination) << kDestinationShift);
    registers_.write32(kCommandLow, low);
    for (uint32_t i = 0; i < spins; ++i) {
        if ((registers_.read32(kCommandLow) & kDeliveryPending) == 0) {
            return true;
        }
    }
    return false;
}

bool LocalApic::sendInit(uint8_t destination, uint32_t spins) const
{
    return sendCommand(destination, kDeliveryInit | kLevelAssert | kLevelTriggered, spins);
}

bool LocalApic::sendInitDeassert(uint8_t destination, uint32_t spins) const
{
    return sendCommand(destination, kShorthandAllIncludingSelf | kDeliveryInit | kLevelTriggered, spins);
}

bool LocalApic::sendStartup(uint8_t destination, uint8_t page, uint32_t spins) const
{
    return sendCommand(destination, kDeliveryStartup | kLevelAssert | page, spins);
}

bool LocalApic::sendFixed(uint8_t destination, uint8_t vector, uint32_t spins) const
{
    if (vector < kLowestVector) {
        return false;
    }
    return sendCommand(destination, kDeliveryFixed | kLevelAssert | vector, spins);
}

uint32_t LocalApic::errorStatus() const
{
    // A write moves the errors seen since the previous write into the
    // register; only then does a read show them (11.5.3).
    registers_.write32(kErrorStatus, 0);
    return registers_.read32(kErrorStatus);
}

} // namespace bsp
