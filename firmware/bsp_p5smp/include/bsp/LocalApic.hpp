// Driver for the local APIC of a Pentium (P54C) processor: each processor's
// own interrupt controller, timer and sender of inter-processor interrupts.
//
// Register and bit names follow the Intel 64 and IA-32 Architectures
// Software Developer's Manual, Volume 3A, chapter "Advanced Programmable
// Interrupt Controller (APIC)": 11.4 (register map, ID, version), 11.5.1
// (local vector table), 11.5.3 (error status), 11.5.4 (timer), 11.6.1
// (interrupt command register), 11.6.2 (logical destinations), 11.8.3
// (task priority), 11.8.4-11.8.5 (IRR, ISR, EOI) and 11.9 (spurious
// interrupt). Every processor sees its own APIC at the same address, so one
// LocalApic object serves whichever processor runs it.
#pragma once

#include <stdint.h>

#include <arch_x86/IoWindow.hpp>

namespace bsp {

class LocalApic {
public:
    /// The architectural default base (MSR IA32_APIC_BASE) and the size of the register page.
    static constexpr uint32_t kDefaultBase = 0xFEE00000u;
    static constexpr uint32_t kWindowBytes = 0x400;

    // Register offsets (11.4, register address map). Every register is a
    // 32-bit word on a 16-byte boundary and must be accessed as one.
    static constexpr uint32_t kId = 0x20;
    static constexpr uint32_t kVersion = 0x30;
    static constexpr uint32_t kTaskPriority = 0x80;
    static constexpr uint32_t kArbitrationPriority = 0x90;
    static constexpr uint32_t kProcessorPriority = 0xA0;
    static constexpr uint32_t kEndOfInterrupt = 0xB0;
    static constexpr uint32_t kLogicalDestination = 0xD0;
    static constexpr uint32_t kDestinationFormat = 0xE0;
    static constexpr uint32_t kSpuriousVector = 0xF0;
    static constexpr uint32_t kInService = 0x100;        // eight words, vectors 0-255
    static constexpr uint32_t kTriggerMode = 0x180;      // eight words
    static constexpr uint32_t kInterruptRequest = 0x200; // eight words
    static constexpr uint32_t kErrorStatus = 0x280;
    static constexpr uint32_t kCommandLow = 0x300;
    static constexpr uint32_t kCommandHigh = 0x310;
    static constexpr uint32_t kLvtTimer = 0x320;
    static constexpr uint32_t kLvtLint0 = 0x350;
    static constexpr uint32_t kLvtLint1 = 0x360;
    static constexpr uint32_t kLvtError = 0x370;
    static constexpr uint32_t kTimerInitialCount = 0x380;
    static constexpr uint32_t kTimerCurrentCount = 0x390;
    static constexpr uint32_t kTimerDivide = 0x3E0;
    /// IRR, ISR and TMR hold 32 vectors per word, words 16 bytes apart (11.8.4).
    static constexpr uint32_t kVectorsPerWord = 32;
    static constexpr uint32_t kVectorWordStride = 0x10;

    // ID and version registers (11.4.6, 11.4.8).
    static constexpr unsigned kIdShift = 24; // the Pentium's ID is bits 24-27
    static constexpr uint32_t kVersionMask = 0xFF;
    static constexpr unsigned kMaximumLvtShift = 16;

    // Spurious-interrupt vector register (11.9).
    static constexpr uint32_t kSoftwareEnable = 1u << 8;
    /// On Pentium and P6 APICs bits 0-3 of the spurious vector are wired to 1.
    static constexpr uint8_t kSpuriousLowBits = 0x0F;

    // Destination format and logical destination (11.6.2.2): the flat model
    // is 1111 in bits 28-31; the Pentium wants bits 0-27 written as ones.
    static constexpr uint32_t kFlatModel = 0xFFFFFFFFu;
    static constexpr unsigned kLogicalIdShift = 24;
    static constexpr unsigned kFlatLogicalIds = 8; // one bit each in bits 24-31

    // Local vector table entries (11.5.1) and the ICR's low word (11.6.1)
    // share these fields.
    static constexpr uint32_t kVectorMask = 0xFF;
    static constexpr uint32_t kDeliveryFixed = 0u << 8;
    static constexpr uint32_t kDeliverySmi = 2u << 8;
    static constexpr uint32_t kDeliveryNmi = 4u << 8;
    static constexpr uint32_t kDeliveryInit = 5u << 8;
    static constexpr uint32_t kDeliveryStartup = 6u << 8;
    static constexpr uint32_t kDeliveryExtInt = 7u << 8;
    static constexpr uint32_t kDestinationLogical = 1u << 11;
    static constexpr uint32_t kDeliveryPending = 1u << 12; // delivery status: 1 = send pending
    static constexpr uint32_t kActiveLow = 1u << 13;      // LINT0/1 input polarity
    static constexpr uint32_t kLevelAssert = 1u << 14;    // ICR level; in LVTs the remote IRR
    static constexpr uint32_t kLevelTriggered = 1u << 15;
    static constexpr uint32_t kLvtMask = 1u << 16;
    static constexpr uint32_t kTimerPeriodic = 1u << 17;
    static constexpr uint32_t kShorthandSelf = 1u << 18;
    static constexpr uint32_t kShorthandAllIncludingSelf = 2u << 18;
    static constexpr uint32_t kShorthandAllExcludingSelf = 3u << 18;
    /// The ICR's destination field is bits 56-63 (the high word's 24-31); the Pentium uses 56-59.
    static constexpr unsigned kDestinationShift = 24;

    /// Vectors 0-15 are illegal for APIC delivery (11.5.2): their use is an error.
    static constexpr uint8_t kLowestVector = 0x10;

    /// Timer divide configuration values (SDM 11.5.4 encoding).
    enum class TimerDivide : uint8_t { By1, By2, By4, By8, By16, By32, By64, By128 };

    /// The divide configuration register's value for @p divide: bits 0, 1 and 3 (11.5.4).
    static constexpr uint32_t divideConfiguration(TimerDivide divide)
    {
        switch (divide) {
        case TimerDivide::By1: return 0xB;
        case TimerDivide::By2: return 0x0;
        case TimerDivide::By4: return 0x1;
        case TimerDivide::By8: return 0x2;
        case TimerDivide::By16: return 0x3;
        case TimerDivide::By32: return 0x8;
        case TimerDivide::By64: return 0x9;
        case TimerDivide::By128: return 0xA;
        }
        return 0xB;
    }

    /// The APIC whose registers @p registers covers (kWindowBytes from the base in IA32_APIC_BASE).
    constexpr explicit LocalApic(arch_x86::IoWindow registers) : registers_(registers) {}

    /// This processor's APIC id (bits 24-27 on the Pentium's APIC, 24-31 read).
    uint8_t id() const;
    /// The version register's version (bits 0-7).
    uint8_t version() const;
    /// The version register's highest LVT entry (bits 16-23): 3 on the Pentium (timer, LINT0, LINT1, error).
    uint8_t maximumLvtEntry() const;

    /// Software-enables the APIC with @p spuriousVector (its low four bits must be 1111 on P5/P6 APICs: enforce, return false otherwise), masks LINT0 (the 8259's ExtINT path is not used) and sets LINT1 to NMI, masks the error LVT, sets the flat logical model and task priority 0.
    /// 0x0F, whose low bits fit but which is an illegal vector, is refused too. The logical id is bit (APIC id mod 8) of the flat model's eight, and the timer is masked until started.
    bool enable(uint8_t spuriousVector);

    /// Signals the end of the interrupt in service.
    void endOfInterrupt() const { registers_.write32(kEndOfInterrupt, 0); }

    /// Starts the timer counting @p initialCount ticks of the bus clock divided by @p divide, again and again, interrupting at @p vector each time it reaches 0. False (and nothing written) for a vector below kLowestVector or a count of 0.
    bool startPeriodic(uint8_t vector, uint32_t initialCount, TimerDivide divide) const;
    /// Starts the timer counting @p initialCount ticks once, interrupting at @p vector when it reaches 0. False as for startPeriodic.
    bool startOneShot(uint8_t vector, uint32_t initialCount, TimerDivide divide) const;
    /// Masks the timer and stops its count.
    void stopTimer() const;
    /// The timer's current count: read on every clock reading, hence inline.
    uint32_t currentCount() const { return registers_.read32(kTimerCurrentCount); }
    /// The count the timer was last started with.
    uint32_t initialCount() const { return registers_.read32(kTimerInitialCount); }

    /// Whether @p vector is requested (IRR): register base + (vector / 32) * 0x10, bit vector % 32.
    bool isRequested(uint8_t vector) const { return vectorBit(kInterruptRequest, vector); }
    /// Whether @p vector is in service (ISR): register base + (vector / 32) * 0x10, bit vector % 32.
    bool isInService(uint8_t vector) const { return vectorBit(kInService, vector); }

    /// Sets the task priority register (bits 4-7: the class below which interrupts are held off).
    void setTaskPriority(uint8_t priority) const;

    /// INIT assert (level-triggered, assert) to the processor with APIC id @p destination (physical destination mode); waits at most @p spins reads of the delivery status, false when it never clears.
    bool sendInit(uint8_t destination, uint32_t spins) const;
    /// INIT deassert (level-triggered, deassert), which the Pentium needs after an INIT: it resets every APIC's arbitration id, so the SDM asks for the "all including self" shorthand; @p destination is written but ignored. Waits as sendInit.
    bool sendInitDeassert(uint8_t destination, uint32_t spins) const;
    /// STARTUP to @p destination, starting it in real mode at @p page * 4 KiB (below 1 MiB). Waits as sendInit.
    bool sendStartup(uint8_t destination, uint8_t page, uint32_t spins) const;
    /// A fixed interrupt at @p vector to @p destination; false without sending for a vector below kLowestVector. Waits as sendInit.
    bool sendFixed(uint8_t destination, uint8_t vector, uint32_t spins) const;

    /// Reads (after writing 0 to it, as the SDM asks) the error status register.
    uint32_t errorStatus() const;

    /// The register window this APIC was built with.
    const arch_x86::IoWindow& window() const { return registers_; }

private:
    bool vectorBit(uint32_t base, uint8_t vector) const
    {
        const uint32_t word = registers_.read32(base + (vector / kVectorsPerWord) * kVectorWordStride);
        return (word & (1u << (vector % kVectorsPerWord))) != 0;
    }

    bool startTimer(uint8_t vector, uint32_t initialCount, TimerDivide divide, uint32_t mode) const;
    bool sendCommand(uint8_t destination, uint32_t low, uint32_t spins) const;

    arch_x86::IoWindow registers_;
};

} // namespace bsp
