#include <bsp/IoApic.hpp>

namespace bsp {

uint32_t IoApic::readRegister(uint8_t index) const
{
    registers_.write32(kSelect, index);
    return registers_.read32(kWindow);
}

void IoApic::writeRegister(uint8_t index, uint32_t value) const
{
    registers_.write32(kSelect, index);
    registers_.write32(kWindow, value);
}

uint8_t IoApic::id() const { return static_cast<uint8_t>((readRegister(kIdRegister) >> kIdShift) & kIdMask); }

uint8_t IoApic::version() const { return static_cast<uint8_t>(readRegister(kVersionRegister) & kVersionMask); }

unsigned IoApic::pinCount() const
{
    const unsigned count = ((readRegister(kVersionRegister) >> kMaximumEntryShift) & kVersionMask) + 1;
    // A larger count could only come from a broken chip, and its pins'
    // register indexes would not fit IOREGSEL.
    return count < kMaximumPins ? count : kMaximumPins;
}

void IoApic::maskAll() const
{
    // Setting the mask bit alone is one write, so no entry is ever half
    // changed; the rest of each entry is left for route() to set.
    const unsigned pins = pinCount();
    for (unsigned pin = 0; pin < pins; ++pin) {
        writeRegister(lowIndex(pin), readRegister(lowIndex(pin)) | kMasked);
    }
}

bool IoApic::route(unsigned pin, uint8_t vector, uint8_t destination, bool activeLow, bool levelTriggered,
                   bool masked) const
{
    if (pin >= pinCount() || vector < kLowestVector) {
        return false;
    }
    const uint32_t low = kDeliveryFixed | vector | (activeLow ? kActiveLow : 0u) |
                         (levelTriggered ? kLevelTriggered : 0u) | (masked ? kMasked : 0u);
    // The entry is two registers written one at a time; with the mask set
    // until the last write, an interrupt arriving in between cannot be sent
    // to the old destination with the new vector, or the reverse.
    writeRegister(lowIndex(pin), low | kMasked);
    writeRegister(highIndex(pin), static_cast<uint32_t>(destination) << kDestinationShift);
    writeRegister(lowIndex(pin), low);
    return true;
}

bool IoApic::setMasked(unsigned pin, bool masked) const
{
    if (pin >= pinCount()) {
        return false;
    }
    const uint32_t low = readRegister(lowIndex(pin));
    writeRegister(lowIndex(pin), masked ? low | kMasked : low & ~kMasked);
    return true;
}

bool IoApic::isMasked(unsigned pin) const { return pin >= pinCount() || (readRegister(lowIndex(pin)) & kMasked) != 0; }

uint32_t IoApic::entryLow(unsigned pin) const { return pin < pinCount() ? readRegister(lowIndex(pin)) : 0; }

uint32_t IoApic::entryHigh(unsigned pin) const { return pin < pinCount() ? readRegister(highIndex(pin)) : 0; }

} // namespace bsp
