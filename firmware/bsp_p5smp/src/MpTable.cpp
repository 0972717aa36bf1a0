#include <bsp/MpTable.hpp>

namespace bsp {

namespace {

// The floating pointer structure (MP spec 4.1): 16 bytes on a 16-byte
// boundary, its bytes summing to 0.
constexpr uint32_t kPointerBytes = 16;
constexpr uint8_t kPointerSignature[4] = {'_', 'M', 'P', '_'};
constexpr unsigned kPointerTableAddress = 4; // physical address of the configuration table
constexpr unsigned kPointerLength = 8;       // in 16-byte paragraphs
constexpr unsigned kPointerRevision = 9;
constexpr unsigned kPointerFeature1 = 11;    // non-zero: a default configuration, no table
constexpr unsigned kPointerFeature2 = 12;
constexpr uint8_t kPointerParagraphs = 1;
constexpr uint8_t kFeature2Imcrp = 1u << 7;  // IMCR present: the board starts in PIC mode

// The specification revisions a pointer and a table may name (4.1, 4.2):
// 1 for version 1.1, 4 for version 1.4.
constexpr uint8_t kRevision11 = 1;
constexpr uint8_t kRevision14 = 4;

// The configuration table header (MP spec 4.2).
constexpr uint32_t kHeaderBytes = 44;
constexpr uint8_t kTableSignature[4] = {'P', 'C', 'M', 'P'};
constexpr unsigned kHeaderBaseLength = 4; // header and base entries, in bytes
constexpr unsigned kHeaderRevision = 6;
constexpr unsigned kHeaderOemId = 8;
constexpr unsigned kOemIdBytes = 8;
constexpr unsigned kHeaderProductId = 16;
constexpr unsigned kProductIdBytes = 12;
constexpr unsigned kHeaderEntryCount = 34;
constexpr unsigned kHeaderLocalApic = 36;
constexpr unsigned kHeaderExtendedLength = 40;   // the extended entries after the base table
constexpr unsigned kHeaderExtendedChecksum = 42; // added to the extended bytes' sum gives 0
// The most this parser reads for one table, base and extended together: far
// more than any BIOS writes, and a bound on a corrupt length's cost.
constexpr uint32_t kMaximumTableBytes = 0x10000;

// The base table's entries (MP spec 4.3): a type byte, then fields by type.
constexpr uint8_t kEntryProcessor = 0;
constexpr uint8_t kEntryBus = 1;
constexpr uint8_t kEntryIoApic = 2;
constexpr uint8_t kEntryIoInterrupt = 3;
constexpr uint8_t kEntryLocalInterrupt = 4;
constexpr uint32_t kProcessorEntryBytes = 20;
constexpr uint32_t kOtherEntryBytes = 8;
constexpr uint32_t kLargestEntryBytes = kProcessorEntryBytes;

// Processor entry (4.3.1).
constexpr unsigned kProcessorApicId = 1;
constexpr unsigned kProcessorApicVersion = 2;
constexpr unsigned kProcessorFlags = 3;
constexpr unsigned kProcessorSignature = 4;
constexpr unsigned kProcessorFeatures = 8;
constexpr uint8_t kProcessorEnabled = 1u << 0;   // EN
constexpr uint8_t kProcessorBootstrap = 1u << 1; // BP

// Bus entry (4.3.2): the type is six characters padded with blanks.
constexpr unsigned kBusId = 1;
constexpr unsigned kBusType = 2;
constexpr unsigned kBusTypeBytes = 6;

// I/O APIC entry (4.3.3).
constexpr unsigned kIoApicId = 1;
constexpr unsigned kIoApicVersion = 2;
constexpr unsigned kIoApicFlags = 3;
constexpr unsigned kIoApicAddress = 4;
constexpr uint8_t kIoApicEnabled = 1u << 0; // EN

// I/O and local interrupt entries (4.3.4, 4.3.5) share one layout.
constexpr unsigned kInterruptType = 1;
constexpr unsigned kInterruptFlags = 2; // 16 bits: PO in 0-1, EL in 2-3
constexpr unsigned kInterruptSourceBus = 4;
constexpr unsigned kInterruptSourceIrq = 5;
constexpr unsigned kInterruptDestination = 6; // I/O APIC id, or local APIC id
constexpr unsigned kInterruptPin = 7;         // INTIN, or LINTIN
constexpr uint8_t kHighestInterruptType = MpConfiguration::kInterruptExtInt;
constexpr unsigned kPolarityShift = 0;
constexpr unsigned kTriggerShift = 2;
constexpr unsigned kFieldMask = 3;
// PO and EL: 00 conforms to the bus, 01 active high / edge, 11 active low /
// level; 10 is reserved.
constexpr unsigned kFieldConforming = 0;
constexpr unsigned kFieldFirst = 1;
constexpr unsigned kFieldReserved = 2;

// Where the floating pointer may be (MP spec chapter 4): the first KiB of
// the extended BIOS data area, whose segment is the BIOS data area's word
// at 0x40E; when there is none, the last KiB of base memory, whose size in
// KiB is the word at 0x413; and the BIOS ROM at 0xF0000-0xFFFFF.
constexpr uint32_t kBdaEbdaSegment = 0x40E;
constexpr uint32_t kBdaBaseMemoryKib = 0x413;
constexpr uint32_t kSearchAreaBytes = 1024;
constexpr uint32_t kBiosRomStart = 0xF0000;
constexpr uint32_t kBiosRomBytes = 0x10000;
// Base memory ends at 640 KiB at most: above it is video memory.
constexpr uint32_t kBaseMemoryLimitKib = 640;

uint16_t le16(const uint8_t* bytes) { return static_cast<uint16_t>(bytes[0] | (bytes[1] << 8)); }

uint32_t le32(const uint8_t* bytes)
{
    return static_cast<uint32_t>(bytes[0]) | (static_cast<uint32_t>(bytes[1]) << 8) |
           (static_cast<uint32_t>(bytes[2]) << 16) | (static_cast<uint32_t>(bytes[3]) << 24);
}

bool sameBytes(const uint8_t* a, const uint8_t* b, unsigned count)
{
    for (unsigned i = 0; i < count; ++i) {
        if (a[i] != b[i]) {
            return false;
        }
    }
    return true;
}

uint8_t sum(const uint8_t* bytes, uint32_t count)
{
    uint8_t total = 0;
    for (uint32_t i = 0; i < count; ++i) {
        total = static_cast<uint8_t>(total + bytes[i]);
    }
    return total;
}

/// Sums @p length bytes from @p address into @p total, reading in small
/// pieces: a table may be 64 KiB and the firmware's stacks are not. False
/// when a byte is unreadable or the range wraps past 4 GiB.
bool sumMemory(const PhysicalMemory& memory, uint32_t address, uint32_t length, uint8_t& total)
{
    if (length != 0 && address > 0xFFFFFFFFu - (length - 1)) {
        return false;
    }
    uint8_t piece[64];
    total = 0;
    for (uint32_t done = 0; done < length;) {
        const uint32_t count = length - done < sizeof piece ? length - done : static_cast<uint32_t>(sizeof piece);
        if (!memory.read(address + done, piece, count)) {
            return false;
        }
        total = static_cast<uint8_t>(total + sum(piece, count));
        done += count;
    }
    return true;
}

/// Copies a blank-padded identification string, dropping trailing blanks
/// and NULs and showing anything unprintable as '?', since it ends up in a
/// console report.
void copyText(const uint8_t* from, unsigned count, char* into)
{
    while (count > 0 && (from[count - 1] == ' ' || from[count - 1] == '\0')) {
        --count;
    }
    for (unsigned i = 0; i < count; ++i) {
        into[i] = from[i] >= 0x20 && from[i] < 0x7F ? static_cast<char>(from[i]) : '?';
    }
    into[count] = '\0';
}

MpBusKind busKind(const uint8_t* type)
{
    // The spec's names are blank-padded; some BIOSes pad with NULs instead.
    char name[kBusTypeBytes + 1];
    copyText(type, kBusTypeBytes, name);
    const auto is = [&name](const char* expected) {
        unsigned i = 0;
        for (; expected[i] != '\0' && name[i] == expected[i]; ++i) {
        }
        return expected[i] == '\0' && name[i] == '\0';
    };
    if (is("ISA")) {
        return MpBusKind::Isa;
    }
    if (is("EISA")) {
        return MpBusKind::Eisa;
    }
    if (is("PCI")) {
        return MpBusKind::Pci;
    }
    return MpBusKind::Other;
}

bool knownRevision(uint8_t revision) { return revision == kRevision11 || revision == kRevision14; }

/// The checks that tell a floating pointer from 16 bytes that happen to
/// start with "_MP_". The length comes first: until it is 1 the checksum's
/// extent is unknown.
MpError checkPointer(const uint8_t* pointer)
{
    if (pointer[kPointerLength] != kPointerParagraphs) {
        return MpError::PointerLength;
    }
    if (sum(pointer, kPointerBytes) != 0) {
        return MpError::PointerChecksum;
    }
    if (!knownRevision(pointer[kPointerRevision])) {
        return MpError::PointerRevision;
    }
    return MpError::None;
}

/// Decodes the PO and EL fields of an interrupt entry; false for the
/// reserved value 10 in either.
bool decodeFlags(uint16_t flags, MpPolarity& polarity, MpTrigger& trigger)
{
    const unsigned po = (flags >> kPolarityShift) & kFieldMask;
    const unsigned el = (flags >> kTriggerShift) & kFieldMask;
    if (po == kFieldReserved || el == kFieldReserved) {
        return false;
    }
    polarity = po == kFieldConforming ? MpPolarity::Conforming : po == kFieldFirst ? MpPolarity::High : MpPolarity::Low;
    trigger = el == kFieldConforming ? MpTrigger::Conforming : el == kFieldFirst ? MpTrigger::Edge : MpTrigger::Level;
    return true;
}

/// Records the base table entry whose bytes are at @p entry; the caller
/// has checked that its type is known and that it lies within the table.
MpError addEntry(const uint8_t* entry, MpConfiguration& configuration, unsigned& bootstrapCount)
{
    switch (entry[0]) {
    case kEntryProcessor: {
        if (configuration.processorCount >= MpConfiguration::kMaximumProcessors) {
            return MpError::TooManyProcessors;
        }
        MpProcessor& processor = configuration.processors[configuration.processorCount++];
        processor.apicId = entry[kProcessorApicId];
        processor.apicVersion = entry[kProcessorApicVersion];
        processor.enabled = (entry[kProcessorFlags] & kProcessorEnabled) != 0;
        processor.bootstrap = (entry[kProcessorFlags] & kProcessorBootstrap) != 0;
        processor.signature = le32(entry + kProcessorSignature);
        processor.features = le32(entry + kProcessorFeatures);
        if (processor.enabled && processor.bootstrap) {
            ++bootstrapCount;
        }
        return MpError::None;
    }
    case kEntryBus: {
        if (configuration.busCount >= MpConfiguration::kMaximumBuses) {
            return MpError::TooManyBuses;
        }
        MpBus& bus = configuration.buses[configuration.busCount++];
        bus.id = entry[kBusId];
        bus.kind = busKind(entry + kBusType);
        return MpError::None;
    }
    case kEntryIoApic: {
        if (configuration.ioApicCount >= MpConfiguration::kMaximumIoApics) {
            return MpError::TooManyIoApics;
        }
        MpIoApic& ioApic = configuration.ioApics[configuration.ioApicCount++];
        ioApic.id = entry[kIoApicId];
        ioApic.version = entry[kIoApicVersion];
        ioApic.enabled = (entry[kIoApicFlags] & kIoApicEnabled) != 0;
        ioApic.address = le32(entry + kIoApicAddress);
        return MpError::None;
    }
    default: {
        MpInterrupt interrupt{};
        interrupt.type = entry[kInterruptType];
        if (interrupt.type > kHighestInterruptType ||
            !decodeFlags(le16(entry + kInterruptFlags), interrupt.polarity, interrupt.trigger)) {
            return MpError::UnknownEntry;
        }
        interrupt.sourceBus = entry[kInterruptSourceBus];
        interrupt.sourceIrq = entry[kInterruptSourceIrq];
        interrupt.ioApicId = entry[kInterruptDestination];
        interrupt.pin = entry[kInterruptPin];
        if (entry[0] == kEntryIoInterrupt) {
            if (configuration.interruptCount >= MpConfiguration::kMaximumInterrupts) {
                return MpError::TooManyInterrupts;
            }
            configuration.interrupts[configuration.interruptCount++] = interrupt;
        } else {
            if (configuration.localInterruptCount >= MpConfiguration::kMaximumLocalInterrupts) {
                return MpError::TooManyInterrupts;
            }
            configuration.localInterrupts[configuration.localInterruptCount++] = interrupt;
        }
        return MpError::None;
    }
    }
}

/// Reads and checks the table a checked floating pointer at @p pointerAddress names.
MpResult parseTable(const PhysicalMemory& memory, uint32_t pointerAddress, const uint8_t* pointer,
                    MpConfiguration& configuration)
{
    configuration.floatingPointerAddress = pointerAddress;
    configuration.imcrPresent = (pointer[kPointerFeature2] & kFeature2Imcrp) != 0;
    if (pointer[kPointerFeature1] != 0) {
        configuration.defaultConfiguration = pointer[kPointerFeature1];
        return {MpError::DefaultConfiguration, pointerAddress};
    }
    const uint32_t table = le32(pointer + kPointerTableAddress);
    configuration.tableAddress = table;

    uint8_t header[kHeaderBytes];
    if (!memory.read(table, header, sizeof header)) {
        return {MpError::TableUnreadable, table};
    }
    if (!sameBytes(header, kTableSignature, sizeof kTableSignature)) {
        return {MpError::TableSignature, table};
    }
    const uint32_t baseLength = le16(header + kHeaderBaseLength);
    const uint32_t extendedLength = le16(header + kHeaderExtendedLength);
    if (baseLength < kHeaderBytes || baseLength + extendedLength > kMaximumTableBytes) {
        return {MpError::TableLength, table};
    }
    uint8_t total = 0;
    if (!sumMemory(memory, table, baseLength, total)) {
        return {MpError::TableUnreadable, table};
    }
    if (total != 0) {
        return {MpError::TableChecksum, table};
    }
    if (!knownRevision(header[kHeaderRevision])) {
        return {MpError::TableRevision, table};
    }
    // The extended entries are not used, but a wrong checksum over them
    // means the BIOS wrote something other than it meant to, so the whole
    // table is suspect. The base table's checksum covers the field.
    if (extendedLength != 0) {
        const uint32_t extended = table + baseLength;
        if (!sumMemory(memory, extended, extendedLength, total)) {
            return {MpError::TableUnreadable, extended};
        }
        if (static_cast<uint8_t>(total + header[kHeaderExtendedChecksum]) != 0) {
            return {MpError::TableChecksum, extended};
        }
    }

    configuration.specRevision = header[kHeaderRevision];
    configuration.localApicAddress = le32(header + kHeaderLocalApic);
    copyText(header + kHeaderOemId, kOemIdBytes, configuration.oemId);
    copyText(header + kHeaderProductId, kProductIdBytes, configuration.productId);

    // Bytes after the last entry and before the base length are tolerated:
    // the checksum covers them and nothing reads them. The entry count
    // cannot make this loop long: every entry is at least 8 bytes of a
    // table of at most 64 KiB, and far fewer fit the configuration's room.
    const unsigned entryCount = le16(header + kHeaderEntryCount);
    unsigned bootstrapCount = 0;
    uint32_t offset = kHeaderBytes;
    for (unsigned i = 0; i < entryCount; ++i) {
        const uint32_t at = table + offset;
        if (offset >= baseLength) {
            return {MpError::EntryTruncated, at};
        }
        uint8_t entry[kLargestEntryBytes];
        if (!memory.read(at, entry, 1)) {
            return {MpError::TableUnreadable, at};
        }
        uint32_t size = 0;
        if (entry[0] == kEntryProcessor) {
            size = kProcessorEntryBytes;
        } else if (entry[0] <= kEntryLocalInterrupt) {
            size = kOtherEntryBytes;
        } else {
            return {MpError::UnknownEntry, at};
        }
        if (size > baseLength - offset) {
            return {MpError::EntryTruncated, at};
        }
        if (!memory.read(at, entry, size)) {
            return {MpError::TableUnreadable, at};
        }
        const MpError error = addEntry(entry, configuration, bootstrapCount);
        if (error != MpError::None) {
            return {error, at};
        }
        offset += size;
    }

    if (bootstrapCount != 1) {
        return {MpError::NoBootProcessor, table};
    }
    bool enabledIoApic = false;
    for (unsigned i = 0; i < configuration.ioApicCount; ++i) {
        enabledIoApic = enabledIoApic || configuration.ioApics[i].enabled;
    }
    if (!enabledIoApic) {
        return {MpError::NoIoApic, table};
    }
    return {MpError::None, pointerAddress};
}

bool readPointer(const PhysicalMemory& memory, uint32_t address, uint8_t* pointer)
{
    return memory.read(address, pointer, kPointerBytes) &&
           sameBytes(pointer, kPointerSignature, sizeof kPointerSignature);
}

} // namespace

const char* mpErrorText(MpError error)
{
    switch (error) {
    case MpError::None: return "the MP tables are valid";
    case MpError::NotFound: return "no MP floating pointer structure was found in the EBDA, base memory or BIOS ROM";
    case MpError::PointerChecksum: return "the MP floating pointer structure's checksum is wrong";
    case MpError::PointerLength: return "the MP floating pointer structure's length is not 16 bytes";
    case MpError::PointerRevision: return "the MP floating pointer structure names a spec revision other than 1.1 or 1.4";
    case MpError::DefaultConfiguration:
        return "the BIOS names an MP default configuration instead of a configuration table, which is not supported";
    case MpError::TableUnreadable: return "the MP configuration table lies outside readable memory";
    case MpError::TableSignature: return "the MP floating pointer does not point at a PCMP configuration table";
    case MpError::TableChecksum: return "the MP configuration table's checksum is wrong";
    case MpError::TableRevision: return "the MP configuration table names a spec revision other than 1.1 or 1.4";
    case MpError::TableLength: return "the MP configuration table's length is shorter than its header or over 64 KiB";
    case MpError::EntryTruncated: return "an MP configuration table entry runs past the end of the table";
    case MpError::UnknownEntry: return "an MP configuration table entry has a type or flags the specification does not define";
    case MpError::TooManyProcessors: return "the MP configuration table lists more processors than DCOS has room for";
    case MpError::TooManyBuses: return "the MP configuration table lists more buses than DCOS has room for";
    case MpError::TooManyIoApics: return "the MP configuration table lists more I/O APICs than DCOS has room for";
    case MpError::TooManyInterrupts:
        return "the MP configuration table lists more interrupt assignments than DCOS has room for";
    case MpError::NoBootProcessor:
        return "the MP configuration table does not name exactly one enabled bootstrap processor";
    case MpError::NoIoApic: return "the MP configuration table lists no enabled I/O APIC";
    }
    return "an unknown MP table error";
}

const MpProcessor* MpConfiguration::bootstrapProcessor() const
{
    for (unsigned i = 0; i < processorCount; ++i) {
        if (processors[i].bootstrap && processors[i].enabled) {
            return &processors[i];
        }
    }
    return nullptr;
}

const MpIoApic* MpConfiguration::ioApic(uint8_t id) const
{
    for (unsigned i = 0; i < ioApicCount; ++i) {
        if (ioApics[i].id == id) {
            return &ioApics[i];
        }
    }
    return nullptr;
}

const MpBus* MpConfiguration::bus(uint8_t id) const
{
    for (unsigned i = 0; i < busCount; ++i) {
        if (buses[i].id == id) {
            return &buses[i];
        }
    }
    return nullptr;
}

bool MpConfiguration::resolve(const MpInterrupt& interrupt, MpBusKind kind, IoApicRoute& route) const
{
    // "Conforming" means what the source bus's own specification says: PCI
    // interrupts are shared, active-low and level-triggered; ISA ones (and,
    // without the EISA edge/level control register to say otherwise, EISA
    // and the rest) active-high and edge-triggered.
    const bool pci = kind == MpBusKind::Pci;
    // A destination of 0xFF means every I/O APIC; the first one stands for
    // them, since a route names one.
    route.ioApicId = interrupt.ioApicId == kAllApics && ioApicCount > 0 ? ioApics[0].id : interrupt.ioApicId;
    route.pin = interrupt.pin;
    route.activeLow = interrupt.polarity == MpPolarity::Low || (interrupt.polarity == MpPolarity::Conforming && pci);
    route.levelTriggered = interrupt.trigger == MpTrigger::Level || (interrupt.trigger == MpTrigger::Conforming && pci);
    return true;
}

bool MpConfiguration::isaRoute(uint8_t irq, IoApicRoute& route) const
{
    for (unsigned i = 0; i < interruptCount; ++i) {
        const MpInterrupt& interrupt = interrupts[i];
        const MpBus* source = bus(interrupt.sourceBus);
        if (interrupt.type == kInterruptInt && source != nullptr && source->kind == MpBusKind::Isa &&
            interrupt.sourceIrq == irq) {
            return resolve(interrupt, source->kind, route);
        }
    }
    return false;
}

bool MpConfiguration::pciRoute(uint8_t busId, uint8_t device, uint8_t pin, IoApicRoute& route) const
{
    // A PCI source IRQ holds the device in bits 2-6 and INTA#-INTD# in bits 0-1.
    constexpr uint8_t kDevices = 32;
    constexpr uint8_t kPins = 4;
    if (device >= kDevices || pin >= kPins) {
        return false;
    }
    const uint8_t sourceIrq = static_cast<uint8_t>((device << 2) | pin);
    for (unsigned i = 0; i < interruptCount; ++i) {
        const MpInterrupt& interrupt = interrupts[i];
        if (interrupt.type != kInterruptInt || interrupt.sourceBus != busId || interrupt.sourceIrq != sourceIrq) {
            continue;
        }
        const MpBus* source = bus(busId);
        if (source != nullptr && source->kind == MpBusKind::Pci) {
            return resolve(interrupt, source->kind, route);
        }
    }
    return false;
}

MpResult parseMpConfiguration(const PhysicalMemory& memory, uint32_t pointerAddress, MpConfiguration& configuration)
{
    configuration = MpConfiguration{};
    uint8_t pointer[kPointerBytes];
    if (!readPointer(memory, pointerAddress, pointer)) {
        return {MpError::NotFound, pointerAddress};
    }
    const MpError error = checkPointer(pointer);
    if (error != MpError::None) {
        return {error, pointerAddress};
    }
    return parseTable(memory, pointerAddress, pointer, configuration);
}

MpResult findMpConfiguration(const PhysicalMemory& memory, MpConfiguration& configuration)
{
    configuration = MpConfiguration{};
    struct Area {
        uint32_t start;
        uint32_t bytes;
    };
    Area areas[3];
    unsigned areaCount = 0;
    uint8_t word[2];
    const uint32_t ebda = memory.read(kBdaEbdaSegment, word, sizeof word) ? uint32_t{le16(word)} << 4 : 0;
    if (ebda != 0) {
        areas[areaCount++] = {ebda, kSearchAreaBytes};
    } else if (memory.read(kBdaBaseMemoryKib, word, sizeof word)) {
        const uint32_t kib = le16(word);
        if (kib >= 1 && kib <= kBaseMemoryLimitKib) {
            areas[areaCount++] = {(kib - 1) * 1024, kSearchAreaBytes};
        }
    }
    areas[areaCount++] = {kBiosRomStart, kBiosRomBytes};

    // A structure that starts with the signature but fails its checks is
    // passed over, since the same bytes may turn up by chance in ROM code;
    // if no good one follows, the first such failure is the answer, as it
    // most likely was the BIOS's damaged pointer.
    MpResult failure{MpError::NotFound, 0};
    for (unsigned a = 0; a < areaCount; ++a) {
        for (uint32_t offset = 0; offset + kPointerBytes <= areas[a].bytes; offset += kPointerBytes) {
            const uint32_t address = areas[a].start + offset;
            uint8_t pointer[kPointerBytes];
            if (!readPointer(memory, address, pointer)) {
                continue;
            }
            const MpError error = checkPointer(pointer);
            if (error == MpError::None) {
                return parseTable(memory, address, pointer, configuration);
            }
            if (failure.error == MpError::NotFound) {
                failure = {error, address};
            }
        }
    }
    return failure;
}

} // namespace bsp
