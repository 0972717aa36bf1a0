// The Intel MultiProcessor Specification 1.4 tables: where the BIOS says
// which processors, buses, I/O APICs and interrupt wires a board has.
//
// SeaBIOS writes them for QEMU's `pc` machine with more than one CPU: a
// floating pointer structure (MP spec 4.1) in the BIOS ROM segment that
// points at a configuration table (4.2) whose entries (4.3) list the two
// Pentiums, the PCI and ISA buses, the I/O APIC and which I/O APIC pin each
// ISA IRQ and PCI interrupt arrives at. The board reads them once at boot
// to learn the APIC ids it must start and route.
//
// Everything read comes from the BIOS and is checked before it is believed:
// checksums, lengths, entry types and every count against the fixed room
// below (the firmware has no heap). Memory is read through PhysicalMemory,
// so the host tests and the fuzz target can hand in a buffer.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace bsp {

/// Reads physical memory for the MP table search; on the board it reads the identity-mapped low memory directly, in tests a buffer.
class PhysicalMemory {
public:
    /// Copies @p bytes from physical @p address into @p into; false when any byte lies outside the readable memory.
    virtual bool read(uint32_t address, void* into, uint32_t bytes) const = 0;

protected:
    ~PhysicalMemory() = default;
};

/// Why the MP tables could not be used (None: they could).
enum class MpError : uint8_t {
    None,
    NotFound,             ///< No floating pointer structure in any search area.
    PointerChecksum,      ///< The floating pointer's bytes do not sum to 0.
    PointerLength,        ///< The floating pointer's length is not one 16-byte paragraph.
    PointerRevision,      ///< The floating pointer names a revision other than 1.1 or 1.4.
    DefaultConfiguration, ///< The BIOS names one of the spec's default configurations instead of a table.
    TableUnreadable,      ///< Part of the configuration table lies outside readable memory.
    TableSignature,       ///< No "PCMP" where the floating pointer points.
    TableChecksum,        ///< The base or the extended table's bytes do not sum to 0.
    TableRevision,        ///< The table names a revision other than 1.1 or 1.4.
    TableLength,          ///< The base length is below the header, or base and extended exceed 64 KiB.
    EntryTruncated,       ///< An entry runs past the base table's length.
    UnknownEntry,         ///< An entry type, interrupt type or flag value the spec does not define.
    TooManyProcessors,    ///< More processor entries than MpConfiguration has room for.
    TooManyBuses,         ///< More bus entries than MpConfiguration has room for.
    TooManyIoApics,       ///< More I/O APIC entries than MpConfiguration has room for.
    TooManyInterrupts,    ///< More interrupt entries than MpConfiguration has room for.
    NoBootProcessor,      ///< Not exactly one enabled processor entry carries the bootstrap flag.
    NoIoApic,             ///< No enabled I/O APIC entry.
};

/// A sentence saying what the error means, e.g. "the MP configuration table's checksum is wrong".
const char* mpErrorText(MpError error);

/// A processor entry (MP spec 4.3.1).
struct MpProcessor {
    uint8_t apicId;
    uint8_t apicVersion;
    bool enabled;   ///< Flag EN: false means the operating system must not use this processor.
    bool bootstrap; ///< Flag BP: the processor that runs the BIOS and this code.
    uint32_t signature; ///< CPUID family, model and stepping as the BIOS saw them.
    uint32_t features;  ///< CPUID leaf 1 EDX as the BIOS saw it.
};

/// An I/O APIC entry (MP spec 4.3.3).
struct MpIoApic {
    uint8_t id;
    uint8_t version;
    bool enabled;
    uint32_t address;
};

/// What a bus entry's type string names (MP spec 4.3.2); the rest are Other.
enum class MpBusKind : uint8_t { Isa, Eisa, Pci, Other };

/// A bus entry (MP spec 4.3.2).
struct MpBus {
    uint8_t id;
    MpBusKind kind;
};

/// The PO field of an interrupt entry (MP spec 4.3.4).
enum class MpPolarity : uint8_t { Conforming, High, Low };
/// The EL field of an interrupt entry (MP spec 4.3.4).
enum class MpTrigger : uint8_t { Conforming, Edge, Level };

/// An I/O interrupt entry (MP spec 4.3.4) or a local interrupt entry (4.3.5).
/// In a local one ioApicId is the destination local APIC id and pin its
/// LINTIN number; 0xFF as a destination means all of them.
struct MpInterrupt {
    uint8_t type /* 0 INT, 1 NMI, 2 SMI, 3 ExtINT */;
    MpPolarity polarity;
    MpTrigger trigger;
    uint8_t sourceBus;
    uint8_t sourceIrq;
    uint8_t ioApicId;
    uint8_t pin;
};

/// Where an interrupt source arrives at an I/O APIC, with the polarity and trigger resolved ("conforming" replaced by the bus's default: high/edge for ISA, EISA and other buses, low/level for PCI).
struct IoApicRoute {
    uint8_t ioApicId;
    uint8_t pin;
    bool activeLow;
    bool levelTriggered;
};

/// What the MP tables say, in fixed room.
class MpConfiguration {
public:
    static constexpr unsigned kMaximumProcessors = 8, kMaximumBuses = 16, kMaximumIoApics = 2, kMaximumInterrupts = 48;
    /// Room for local interrupt entries: two LINTIN wires for each processor.
    static constexpr unsigned kMaximumLocalInterrupts = 2 * kMaximumProcessors;
    /// Interrupt entry types (MP spec 4.3.4).
    static constexpr uint8_t kInterruptInt = 0, kInterruptNmi = 1, kInterruptSmi = 2, kInterruptExtInt = 3;
    /// An interrupt entry's destination that means every I/O APIC or every local APIC (MP spec 4.3.4, 4.3.5).
    static constexpr uint8_t kAllApics = 0xFF;

    uint32_t floatingPointerAddress = 0;
    uint32_t tableAddress = 0;
    uint8_t specRevision = 0;
    bool imcrPresent = false;
    uint32_t localApicAddress = 0;
    /// The OEM and product strings, trailing blanks removed, anything unprintable as '?'.
    char oemId[9] = {};
    char productId[13] = {};
    MpProcessor processors[kMaximumProcessors] = {};
    unsigned processorCount = 0;
    MpBus buses[kMaximumBuses] = {};
    unsigned busCount = 0;
    MpIoApic ioApics[kMaximumIoApics] = {};
    unsigned ioApicCount = 0;
    /// The I/O interrupt entries (type 3), in table order.
    MpInterrupt interrupts[kMaximumInterrupts] = {};
    unsigned interruptCount = 0;
    /// The local interrupt entries (type 4), in table order; they count against TooManyInterrupts too.
    MpInterrupt localInterrupts[kMaximumLocalInterrupts] = {};
    unsigned localInterruptCount = 0;
    /// MP feature byte 1 when it names a default configuration (MpError::DefaultConfiguration), else 0.
    uint8_t defaultConfiguration = 0;

    /// The bootstrap processor's entry, or null.
    const MpProcessor* bootstrapProcessor() const;
    /// The I/O APIC route of ISA IRQ @p irq (an I/O interrupt entry of type INT from an ISA bus with that source IRQ); false when the table names none.
    bool isaRoute(uint8_t irq, IoApicRoute& route) const;
    /// The route of PCI bus @p bus, device @p device, interrupt pin @p pin (0 = INTA# .. 3 = INTD#): source IRQ encodes (device << 2) | pin (MP spec D.3); false when none.
    bool pciRoute(uint8_t bus, uint8_t device, uint8_t pin, IoApicRoute& route) const;
    /// The I/O APIC entry with id @p id (the first, should the table list an id twice), or null.
    const MpIoApic* ioApic(uint8_t id) const;
    /// The bus entry with id @p id (the first, should the table list an id twice), or null.
    const MpBus* bus(uint8_t id) const;

private:
    bool resolve(const MpInterrupt& interrupt, MpBusKind kind, IoApicRoute& route) const;
};

/// Where a search failed or what it found, with the address the error concerns (for a panic report).
/// On success the address is the floating pointer's.
struct MpResult {
    MpError error;
    uint32_t address;
};

/// Searches the three areas for the floating pointer, checks it and the configuration table and its entries, and fills @p configuration. O(table).
/// Every count is bounded by the kMaximum* constants (exceeding one is an error, not a truncation); every read is bounds-checked through @p memory; a base table length below the header or above 64 KiB, an entry running past the table, an unknown entry type, no enabled bootstrap processor or no I/O APIC are errors.
/// After an error @p configuration holds what was read up to it, within its bounds.
MpResult findMpConfiguration(const PhysicalMemory& memory, MpConfiguration& configuration);

/// The same, for a floating pointer known to be at @p pointerAddress (tests and the fuzz target use it).
MpResult parseMpConfiguration(const PhysicalMemory& memory, uint32_t pointerAddress, MpConfiguration& configuration);

} // namespace bsp
