#include <bsp/Pic8259.hpp>

namespace bsp {

void Pic8259::initialise(uint8_t vectorBase)
{
    // ICW1 starts the sequence on both chips; ICW2-ICW4 follow on the data port.
    master_.write8(commandRegister, icw1Select | icw1Icw4Needed);
    slave_.write8(commandRegister, icw1Select | icw1Icw4Needed);
    master_.write8(dataRegister, vectorBase);                             // ICW2
    slave_.write8(dataRegister, static_cast<uint8_t>(vectorBase + 8));     // ICW2
    master_.write8(dataRegister, static_cast<uint8_t>(1u << cascadeLine)); // ICW3: slave on IR2
    slave_.write8(dataRegister, cascadeLine);                               // ICW3: slave id 2
    master_.write8(dataRegister, icw4Mode8086);                             // ICW4
    slave_.write8(dataRegister, icw4Mode8086);                              // ICW4
    // The slave's line stays unmasked on the master, or no IRQ 8-15 can arrive.
    maskBits_ = static_cast<uint16_t>(0xFFFFu & ~(1u << cascadeLine));
    writeMask();
}

void Pic8259::writeMask()
{
    const uint16_t combined = static_cast<uint16_t>(maskBits_ | overlayBits_);
    master_.write8(dataRegister, static_cast<uint8_t>(combined & 0xFF)); // OCW1
    slave_.write8(dataRegister, static_cast<uint8_t>(combined >> 8));    // OCW1
}

void Pic8259::setOverlayMask(uint16_t overlay)
{
    // The cascade input must stay open or no slave line gets through.
    overlay = static_cast<uint16_t>(overlay & ~(1u << cascadeLine));
    if (overlay != overlayBits_) {
        overlayBits_ = overlay;
        writeMask();
    }
}

void Pic8259::mask(unsigned line)
{
    if (line >= lineCount || line == cascadeLine) {
        return;
    }
    maskBits_ = static_cast<uint16_t>(maskBits_ | (1u << line));
    writeMask();
}

void Pic8259::unmask(unsigned line)
{
    if (line >= lineCount) {
        return;
    }
    maskBits_ = static_cast<uint16_t>(maskBits_ & ~(1u << line));
    writeMask();
}

bool Pic8259::isMasked(unsigned line) const
{
    return line < lineCount && (maskBits_ & (1u << line)) != 0;
}

uint16_t Pic8259::readRequestRegister() const
{
    master_.write8(commandRegister, ocw3ReadIrr);
    slave_.write8(commandRegister, ocw3ReadIrr);
    return static_cast<uint16_t>(master_.read8(commandRegister) | (slave_.read8(commandRegister) << 8));
}

uint16_t Pic8259::readInServiceRegister() const
{
    master_.write8(commandRegister, ocw3ReadIsr);
    slave_.write8(commandRegister, ocw3ReadIsr);
    return static_cast<uint16_t>(master_.read8(commandRegister) | (slave_.read8(commandRegister) << 8));
}

uint16_t Pic8259::readMaskRegisters() const
{
    return static_cast<uint16_t>(master_.read8(dataRegister) | (slave_.read8(dataRegister) << 8));
}

bool Pic8259::isGenuineLowestLine(unsigned line) const
{
    return (readInServiceRegister() & (1u << line)) != 0;
}

} // namespace bsp
