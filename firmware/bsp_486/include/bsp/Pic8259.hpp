// Driver for a cascaded pair of Intel 8259A programmable interrupt controllers.
//
// Register and bit names follow the Intel 8259A datasheet (order number
// 231468), sections "Initialization Command Words" (ICW1-ICW4) and
// "Operation Command Words" (OCW1-OCW3).
#pragma once

#include <stdint.h>

#include <arch_x86/IoWindow.hpp>

namespace bsp {

class Pic8259 {
public:
    /// Number of interrupt request lines of the master-slave pair.
    static constexpr unsigned lineCount = 16;
    /// The master input the slave's INT output is wired to on a PC/AT.
    static constexpr unsigned cascadeLine = 2;

    // Register offsets within each chip's two-port window (A0 = 0 or 1).
    static constexpr uint8_t commandRegister = 0; // ICW1, OCW2, OCW3 (A0 = 0)
    static constexpr uint8_t dataRegister = 1;    // ICW2-ICW4, OCW1 = IMR (A0 = 1)

    // ICW1 bits (A0 = 0, D4 = 1).
    static constexpr uint8_t icw1Icw4Needed = 1u << 0;  // IC4
    static constexpr uint8_t icw1Single = 1u << 1;      // SNGL: no cascade
    static constexpr uint8_t icw1LevelTriggered = 1u << 3; // LTIM
    static constexpr uint8_t icw1Select = 1u << 4;      // identifies ICW1
    // ICW4 bits.
    static constexpr uint8_t icw4Mode8086 = 1u << 0;    // uPM
    static constexpr uint8_t icw4AutoEoi = 1u << 1;     // AEOI
    static constexpr uint8_t icw4SpecialFullyNested = 1u << 4; // SFNM
    // OCW2: R SL EOI in D7-D5, level in D2-D0.
    static constexpr uint8_t ocw2NonSpecificEoi = 0x20;
    static constexpr uint8_t ocw2SpecificEoi = 0x60;
    // OCW3 (D4 = 0, D3 = 1): RR and RIS select which register the next read returns.
    static constexpr uint8_t ocw3ReadIrr = 0x0A;
    static constexpr uint8_t ocw3ReadIsr = 0x0B;

    /// The pair at the given windows; nothing is touched until initialise().
    Pic8259(arch_x86::IoWindow master, arch_x86::IoWindow slave) : master_(master), slave_(slave) {}

    /// Programs both chips for edge-triggered, cascaded, fully nested
    /// 8086 mode, delivering IRQ 0-7 at vectorBase and IRQ 8-15 at
    /// vectorBase + 8, with every line masked.
    void initialise(uint8_t vectorBase);

    void mask(unsigned line);
    void unmask(unsigned line);
    /// True when the line is masked in the IMR.
    bool isMasked(unsigned line) const;
    /// The 16-bit interrupt mask (bit n set = IRQ n masked).
    uint16_t maskBits() const { return maskBits_; }

    /// Masks further lines on top of mask(), without changing what mask()
    /// recorded: the running task's interrupt level uses it.
    void setOverlayMask(uint16_t overlay);

    /// The 16-bit interrupt request register: lines asserting a request.
    uint16_t readRequestRegister() const;
    /// The 16-bit in-service register: lines being serviced.
    uint16_t readInServiceRegister() const;
    /// The 16-bit interrupt mask register (OCW1) as the chips hold it: what
    /// mask() recorded and the overlay together.
    uint16_t readMaskRegisters() const;

    /// isGenuine() for line 7 or 15: whether its in-service bit is set.
    bool isGenuineLowestLine(unsigned line) const;

    /// True when an interrupt on line was a real request. The 8259A
    /// reports IRQ 7 (or 15 on the slave) when a request goes away before
    /// the acknowledge cycle; such a spurious interrupt has no in-service
    /// bit and must not get an EOI on its own chip. Only lines 7 and 15 can
    /// be spurious, so only they cost a register read.
    bool isGenuine(unsigned line) const { return (line & 7u) != 7u || isGenuineLowestLine(line); }

    /// Ends the interrupt on line with specific EOIs, slave first. Inline:
    /// every interrupt ends here, and the call would cost more than the
    /// one or two port writes.
    void endOfInterrupt(unsigned line)
    {
        if (line >= 8) {
            slave_.write8(commandRegister, static_cast<uint8_t>(ocw2SpecificEoi | (line - 8)));
            master_.write8(commandRegister, static_cast<uint8_t>(ocw2SpecificEoi | cascadeLine));
        } else {
            master_.write8(commandRegister, static_cast<uint8_t>(ocw2SpecificEoi | line));
        }
    }

private:
    void writeMask();

    arch_x86::IoWindow master_;
    arch_x86::IoWindow slave_;
    uint16_t maskBits_ = 0xFFFF;
    uint16_t overlayBits_ = 0;
};

} // namespace bsp
