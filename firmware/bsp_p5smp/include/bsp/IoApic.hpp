// Driver for an Intel 82093AA I/O APIC: the board's interrupt inputs (ISA
// IRQs and PCI interrupt lines, one pin each), each routed by a redirection
// entry to a vector on a chosen processor's local APIC.
//
// Register and bit names follow the Intel 82093AA I/O APIC datasheet:
// section 3.1 for the register select / window pair that is all the chip
// shows in memory, 3.2.1-3.2.3 for the ID, version and arbitration
// registers and 3.2.4 for the redirection table.
#pragma once

#include <stdint.h>

#include <arch_x86/IoWindow.hpp>

namespace bsp {

class IoApic {
public:
    /// The base the BIOS and QEMU give the first I/O APIC, and the size of its register window.
    static constexpr uint32_t kDefaultBase = 0xFEC00000u;
    static constexpr uint32_t kWindowBytes = 0x20;

    // The memory-mapped pair (3.1): the index of a register goes into
    // IOREGSEL, and IOWIN then reads or writes that register. Both are
    // accessed as 32-bit words.
    static constexpr uint32_t kSelect = 0x00; // IOREGSEL
    static constexpr uint32_t kWindow = 0x10; // IOWIN

    // Register indexes (3.2).
    static constexpr uint8_t kIdRegister = 0x00;           // IOAPICID
    static constexpr uint8_t kVersionRegister = 0x01;      // IOAPICVER
    static constexpr uint8_t kArbitrationRegister = 0x02;  // IOAPICARB
    static constexpr uint8_t kRedirectionBase = 0x10;      // IOREDTBL: pin n's low word at 0x10 + 2n, high at 0x11 + 2n

    // IOAPICID and IOAPICVER fields (3.2.1, 3.2.2).
    static constexpr unsigned kIdShift = 24;
    static constexpr uint32_t kIdMask = 0x0F; // bits 24-27
    static constexpr uint32_t kVersionMask = 0xFF;
    static constexpr unsigned kMaximumEntryShift = 16; // bits 16-23: the number of entries less one

    // Redirection entry, low word (3.2.4).
    static constexpr uint32_t kVectorMask = 0xFF;
    static constexpr uint32_t kDeliveryFixed = 0u << 8;
    static constexpr uint32_t kDeliveryLowestPriority = 1u << 8;
    static constexpr uint32_t kDeliverySmi = 2u << 8;
    static constexpr uint32_t kDeliveryNmi = 4u << 8;
    static constexpr uint32_t kDeliveryInit = 5u << 8;
    static constexpr uint32_t kDeliveryExtInt = 7u << 8;
    static constexpr uint32_t kDestinationLogical = 1u << 11; // 0: physical, an APIC id
    static constexpr uint32_t kDeliveryPending = 1u << 12;    // read-only
    static constexpr uint32_t kActiveLow = 1u << 13;
    static constexpr uint32_t kRemoteIrr = 1u << 14;          // read-only
    static constexpr uint32_t kLevelTriggered = 1u << 15;
    static constexpr uint32_t kMasked = 1u << 16;
    // Redirection entry, high word: the destination in bits 56-63 of the
    // entry; in physical mode an APIC id in bits 56-59.
    static constexpr unsigned kDestinationShift = 24;

    /// Vectors 0-15 are illegal for APIC delivery.
    static constexpr uint8_t kLowestVector = 0x10;
    /// The most pins an 8-bit register index can reach (0x10 + 2n + 1 <= 0xFF); the 82093AA has 24.
    static constexpr unsigned kMaximumPins = 120;

    /// The I/O APIC whose select and window registers @p registers covers (kWindowBytes from its base).
    constexpr explicit IoApic(arch_x86::IoWindow registers) : registers_(registers) {}

    /// The I/O APIC's id (IOAPICID bits 24-27).
    uint8_t id() const;
    /// The I/O APIC's version (IOAPICVER bits 0-7; 0x11 on the 82093AA).
    uint8_t version() const;
    /// Number of redirection entries (max redirection entry + 1, bits 16-23 of the version register), at most kMaximumPins.
    unsigned pinCount() const;

    /// Masks every pin (at boot, before routing).
    void maskAll() const;
    /// Routes @p pin to @p vector on the processor with APIC id @p destination, fixed delivery, physical mode, with the given polarity and trigger, masked or not. false for a pin beyond pinCount() or a vector below 0x10.
    /// The entry stays masked while it changes: the low word is written masked, then the high word, then the low word as asked.
    bool route(unsigned pin, uint8_t vector, uint8_t destination, bool activeLow, bool levelTriggered, bool masked) const;
    /// Masks or unmasks a routed pin, leaving the rest of its entry; false for a pin beyond pinCount().
    bool setMasked(unsigned pin, bool masked) const;
    /// Whether @p pin is masked; true for a pin beyond pinCount(), which cannot deliver anything.
    bool isMasked(unsigned pin) const;

    /// The low word of @p pin's redirection entry (for reports and tests); 0 for a pin beyond pinCount().
    uint32_t entryLow(unsigned pin) const;
    /// The high word of @p pin's redirection entry; 0 for a pin beyond pinCount().
    uint32_t entryHigh(unsigned pin) const;

    /// The register window this I/O APIC was built with.
    const arch_x86::IoWindow& window() const { return registers_; }

private:
    uint32_t readRegister(uint8_t index) const;
    void writeRegister(uint8_t index, uint32_t value) const;
    static uint8_t lowIndex(unsigned pin) { return static_cast<uint8_t>(kRedirectionBase + 2 * pin); }
    static uint8_t highIndex(unsigned pin) { return static_cast<uint8_t>(kRedirectionBase + 2 * pin + 1); }

    arch_x86::IoWindow registers_;
};

} // namespace bsp
