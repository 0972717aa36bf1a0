#include <bsp/MpTable.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <set>
#include <string>
#include <vector>

namespace {

using bsp::MpError;

// The first MiB of a PC, readable as physical memory; reads past its end
// (or into a hole a test punches) fail as on a board without that memory.
class LowMemory final : public bsp::PhysicalMemory {
public:
    LowMemory() : bytes_(0x100000, 0) {}

    bool read(uint32_t address, void* into, uint32_t bytes) const override
    {
        const uint64_t end = uint64_t{address} + bytes;
        if (end > bytes_.size() || (address < holeEnd_ && end > holeStart_)) {
            return false;
        }
        std::memcpy(into, bytes_.data() + address, bytes);
        return true;
    }

    void place(uint32_t address, const std::vector<uint8_t>& data)
    {
        ASSERT_LE(uint64_t{address} + data.size(), bytes_.size());
        std::memcpy(bytes_.data() + address, data.data(), data.size());
    }

    void word(uint32_t address, uint16_t value) { place(address, {uint8_t(value), uint8_t(value >> 8)}); }
    void hole(uint32_t start, uint32_t end)
    {
        holeStart_ = start;
        holeEnd_ = end;
    }
    uint8_t& at(uint32_t address) { return bytes_[address]; }

private:
    std::vector<uint8_t> bytes_;
    uint32_t holeStart_ = 0;
    uint32_t holeEnd_ = 0;
};

void put16(std::vector<uint8_t>& out, size_t at, uint16_t value)
{
    out[at] = uint8_t(value);
    out[at + 1] = uint8_t(value >> 8);
}

void put32(std::vector<uint8_t>& out, size_t at, uint32_t value)
{
    put16(out, at, uint16_t(value));
    put16(out, at + 2, uint16_t(value >> 16));
}

uint8_t byteSum(const std::vector<uint8_t>& bytes, size_t from, size_t count)
{
    uint8_t total = 0;
    for (size_t i = from; i < from + count; ++i) {
        total = uint8_t(total + bytes[i]);
    }
    return total;
}

// Writes an MP floating pointer structure (MP spec 4.1) with a correct checksum.
std::vector<uint8_t> floatingPointer(uint32_t table, uint8_t revision = 4, uint8_t feature1 = 0, uint8_t feature2 = 0,
                                     uint8_t length = 1)
{
    std::vector<uint8_t> out(16, 0);
    std::memcpy(out.data(), "_MP_", 4);
    put32(out, 4, table);
    out[8] = length;
    out[9] = revision;
    out[11] = feature1;
    out[12] = feature2;
    out[10] = uint8_t(-byteSum(out, 0, 16));
    return out;
}

// Flags of interrupt entries: PO in bits 0-1, EL in bits 2-3.
constexpr uint16_t kConforming = 0x0;
constexpr uint16_t kHighEdge = 0x5;
constexpr uint16_t kHighLevel = 0xD;
constexpr uint16_t kLowEdge = 0x7;
constexpr uint16_t kLowLevel = 0xF;

// Builds a configuration table (MP spec 4.2, 4.3) entry by entry and
// writes it with correct checksums; tests then break one thing.
class TableBuilder {
public:
    uint8_t revision = 4;
    std::string oem = "BOCHSCPU";
    std::string product = "0.1         ";
    uint32_t localApic = 0xFEE00000;
    std::vector<uint8_t> extended;
    // When set, replace what build() computes.
    int baseLengthOverride = -1;
    int entryCountOverride = -1;

    void processor(uint8_t id, uint8_t flags, uint8_t version = 0x14)
    {
        std::vector<uint8_t> e(20, 0);
        e[0] = 0;
        e[1] = id;
        e[2] = version;
        e[3] = flags;
        put32(e, 4, 0x0543);     // family 5, model 4, stepping 3: a Pentium MMX
        put32(e, 8, 0x008001BF); // FPU, VME, DE, PSE, TSC, MSR, MCE, CX8, APIC, MMX
        add(e);
    }

    void bus(uint8_t id, const char* type)
    {
        std::vector<uint8_t> e(8, 0);
        e[0] = 1;
        e[1] = id;
        std::memcpy(e.data() + 2, type, 6);
        add(e);
    }

    void ioApic(uint8_t id, uint8_t flags = 1, uint32_t address = 0xFEC00000)
    {
        std::vector<uint8_t> e(8, 0);
        e[0] = 2;
        e[1] = id;
        e[2] = 0x11;
        e[3] = flags;
        put32(e, 4, address);
        add(e);
    }

    void interrupt(uint8_t entryType, uint8_t type, uint16_t flags, uint8_t bus, uint8_t irq, uint8_t apic,
                   uint8_t pin)
    {
        std::vector<uint8_t> e(8, 0);
        e[0] = entryType;
        e[1] = type;
        put16(e, 2, flags);
        e[4] = bus;
        e[5] = irq;
        e[6] = apic;
        e[7] = pin;
        add(e);
    }

    void ioInterrupt(uint8_t type, uint16_t flags, uint8_t bus, uint8_t irq, uint8_t apic, uint8_t pin)
    {
        interrupt(3, type, flags, bus, irq, apic, pin);
    }

    void localInterrupt(uint8_t type, uint16_t flags, uint8_t bus, uint8_t irq, uint8_t apic, uint8_t lint)
    {
        interrupt(4, type, flags, bus, irq, apic, lint);
    }

    void raw(const std::vector<uint8_t>& bytes) { add(bytes); }

    std::vector<uint8_t> build() const
    {
        std::vector<uint8_t> out(44, 0);
        std::memcpy(out.data(), "PCMP", 4);
        const size_t base = 44 + entries_.size();
        put16(out, 4, uint16_t(baseLengthOverride >= 0 ? baseLengthOverride : base));
        out[6] = revision;
        std::memcpy(out.data() + 8, oem.data(), std::min<size_t>(oem.size(), 8));
        std::memcpy(out.data() + 16, product.data(), std::min<size_t>(product.size(), 12));
        put16(out, 34, uint16_t(entryCountOverride >= 0 ? entryCountOverride : count_));
        put32(out, 36, localApic);
        put16(out, 40, uint16_t(extended.size()));
        out[42] = uint8_t(-byteSum(extended, 0, extended.size()));
        out.insert(out.end(), entries_.begin(), entries_.end());
        // The checksum covers the base length the header states, as far as
        // this buffer reaches.
        const size_t covered = std::min(out.size(), size_t(out[4] | (out[5] << 8)));
        out[7] = uint8_t(-byteSum(out, 0, covered));
        out.insert(out.end(), extended.begin(), extended.end());
        return out;
    }

private:
    void add(const std::vector<uint8_t>& e)
    {
        entries_.insert(entries_.end(), e.begin(), e.end());
        ++count_;
    }

    std::vector<uint8_t> entries_;
    unsigned count_ = 0;
};

constexpr uint8_t kEnabled = 1;
constexpr uint8_t kBootstrap = 2;
constexpr uint8_t kPciBus = 0;
constexpr uint8_t kIsaBus = 1;
constexpr uint8_t kIoApicId = 2;

// What SeaBIOS writes for QEMU's pc machine with two CPUs: the processors
// (APIC ids 0 and 1, the bootstrap one first), the PCI bus 0 and the ISA
// bus after it, one I/O APIC, a PCI interrupt, the ISA IRQs (IRQ 0 on pin 2
// for the timer override, no IRQ 2, the rest on their own pins) and the
// local interrupts (ExtINT on LINT0 of the BSP, NMI on LINT1 of all).
TableBuilder seabiosTable(uint8_t ioApicId = kIoApicId)
{
    TableBuilder t;
    t.processor(0, kEnabled | kBootstrap);
    t.processor(1, kEnabled);
    t.bus(kPciBus, "PCI   ");
    t.bus(kIsaBus, "ISA   ");
    t.ioApic(ioApicId);
    // PCI device 1 INTA# and device 3 INTA# (bus 0), as SeaBIOS lists them.
    t.ioInterrupt(0, kConforming, kPciBus, (1 << 2) | 0, ioApicId, 11);
    t.ioInterrupt(0, kHighEdge, kPciBus, (3 << 2) | 0, ioApicId, 10);
    for (uint8_t irq = 0; irq < 16; ++irq) {
        if (irq == 2) {
            continue;
        }
        const uint16_t flags = irq == 9 ? kHighLevel : irq == 14 ? kLowEdge : kConforming;
        t.ioInterrupt(0, flags, kIsaBus, irq, ioApicId, irq == 0 ? 2 : irq);
    }
    t.localInterrupt(3, kConforming, kIsaBus, 0, 0, 0);
    t.localInterrupt(1, kConforming, kIsaBus, 0, 0xFF, 1);
    return t;
}

constexpr uint32_t kRomPointer = 0xF5A70;
constexpr uint32_t kRomTable = 0xF5A80;

LowMemory withRomTable(const TableBuilder& table)
{
    LowMemory memory;
    memory.place(kRomPointer, floatingPointer(kRomTable));
    memory.place(kRomTable, table.build());
    return memory;
}

MpError parseTable(const TableBuilder& table, bsp::MpConfiguration& configuration)
{
    const LowMemory memory = withRomTable(table);
    return bsp::parseMpConfiguration(memory, kRomPointer, configuration).error;
}

MpError parseTable(const TableBuilder& table)
{
    bsp::MpConfiguration configuration;
    return parseTable(table, configuration);
}

TEST(MpTable, FindsSeabiosTablesInTheBiosRom)
{
    const LowMemory memory = withRomTable(seabiosTable());
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    ASSERT_EQ(result.error, MpError::None) << bsp::mpErrorText(result.error);
    EXPECT_EQ(result.address, kRomPointer);
    EXPECT_EQ(c.floatingPointerAddress, kRomPointer);
    EXPECT_EQ(c.tableAddress, kRomTable);
    EXPECT_EQ(c.specRevision, 4);
    EXPECT_FALSE(c.imcrPresent);
    EXPECT_EQ(c.localApicAddress, 0xFEE00000u);
    EXPECT_STREQ(c.oemId, "BOCHSCPU");
    EXPECT_STREQ(c.productId, "0.1"); // Trailing blanks go.

    ASSERT_EQ(c.processorCount, 2u);
    EXPECT_EQ(c.processors[0].apicId, 0);
    EXPECT_EQ(c.processors[0].apicVersion, 0x14);
    EXPECT_TRUE(c.processors[0].enabled);
    EXPECT_TRUE(c.processors[0].bootstrap);
    EXPECT_EQ(c.processors[0].signature, 0x0543u);
    EXPECT_EQ(c.processors[0].features, 0x008001BFu);
    EXPECT_EQ(c.processors[1].apicId, 1);
    EXPECT_TRUE(c.processors[1].enabled);
    EXPECT_FALSE(c.processors[1].bootstrap);
    ASSERT_NE(c.bootstrapProcessor(), nullptr);
    EXPECT_EQ(c.bootstrapProcessor()->apicId, 0);

    ASSERT_EQ(c.busCount, 2u);
    EXPECT_EQ(c.buses[0].id, kPciBus);
    EXPECT_EQ(c.buses[0].kind, bsp::MpBusKind::Pci);
    EXPECT_EQ(c.buses[1].id, kIsaBus);
    EXPECT_EQ(c.buses[1].kind, bsp::MpBusKind::Isa);

    ASSERT_EQ(c.ioApicCount, 1u);
    const bsp::MpIoApic* ioApic = c.ioApic(kIoApicId);
    ASSERT_NE(ioApic, nullptr);
    EXPECT_EQ(ioApic->address, 0xFEC00000u);
    EXPECT_EQ(ioApic->version, 0x11);
    EXPECT_TRUE(ioApic->enabled);
    EXPECT_EQ(c.ioApic(7), nullptr);

    EXPECT_EQ(c.interruptCount, 2u + 15u);
    ASSERT_EQ(c.localInterruptCount, 2u);
    EXPECT_EQ(c.localInterrupts[0].type, bsp::MpConfiguration::kInterruptExtInt);
    EXPECT_EQ(c.localInterrupts[0].ioApicId, 0);
    EXPECT_EQ(c.localInterrupts[0].pin, 0);
    EXPECT_EQ(c.localInterrupts[1].type, bsp::MpConfiguration::kInterruptNmi);
    EXPECT_EQ(c.localInterrupts[1].ioApicId, 0xFF);
    EXPECT_EQ(c.localInterrupts[1].pin, 1);
}

TEST(MpTable, FindsThePointerInTheFirstKibOfTheEbda)
{
    LowMemory memory;
    memory.word(0x40E, 0x9FC0);
    memory.word(0x413, 639);
    memory.place(0x9FC00 + 0x3F0, floatingPointer(0x9FD00)); // The last paragraph of the first KiB.
    memory.place(0x9FD00, seabiosTable().build());
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    EXPECT_EQ(result.error, MpError::None);
    EXPECT_EQ(result.address, 0x9FC00u + 0x3F0u);
    EXPECT_EQ(c.tableAddress, 0x9FD00u);
}

TEST(MpTable, FindsThePointerInTheLastKibOfBaseMemoryWhenThereIsNoEbda)
{
    LowMemory memory;
    memory.word(0x40E, 0);
    memory.word(0x413, 639);
    memory.place(639 * 1024 - 1024, floatingPointer(0x9F000));
    memory.place(0x9F000, seabiosTable().build());
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    EXPECT_EQ(result.error, MpError::None);
    EXPECT_EQ(result.address, 638u * 1024);
}

TEST(MpTable, TheLastKibOfBaseMemoryIsOnlySearchedWithoutAnEbda)
{
    LowMemory memory;
    memory.word(0x40E, 0x9FC0);
    memory.word(0x413, 639);
    memory.place(638 * 1024, floatingPointer(0x9F000));
    memory.place(0x9F000, seabiosTable().build());
    bsp::MpConfiguration c;
    EXPECT_EQ(bsp::findMpConfiguration(memory, c).error, MpError::NotFound);
}

TEST(MpTable, FindsThePointerAnywhereInTheBiosRom)
{
    for (const uint32_t at : {0xF0000u, 0xFFFF0u}) {
        LowMemory memory;
        memory.place(at, floatingPointer(0xF8000));
        memory.place(0xF8000, seabiosTable().build());
        bsp::MpConfiguration c;
        const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
        EXPECT_EQ(result.error, MpError::None) << std::hex << at;
        EXPECT_EQ(result.address, at);
    }
}

TEST(MpTable, TheEbdaIsPreferredOverTheBiosRom)
{
    LowMemory memory = withRomTable(seabiosTable());
    TableBuilder ebdaTable = seabiosTable();
    ebdaTable.oem = "EBDA";
    memory.word(0x40E, 0x9FC0);
    memory.place(0x9FC00, floatingPointer(0x9FC10));
    memory.place(0x9FC10, ebdaTable.build());
    bsp::MpConfiguration c;
    ASSERT_EQ(bsp::findMpConfiguration(memory, c).error, MpError::None);
    EXPECT_EQ(c.floatingPointerAddress, 0x9FC00u);
    EXPECT_STREQ(c.oemId, "EBDA");
}

TEST(MpTable, APointerOffA16ByteBoundaryIsNotFound)
{
    LowMemory memory;
    memory.place(0xF0008, floatingPointer(0xF8000));
    memory.place(0xF8000, seabiosTable().build());
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    EXPECT_EQ(result.error, MpError::NotFound);
    EXPECT_EQ(result.address, 0u);
}

TEST(MpTable, EmptyOrUnreadableMemoryFindsNothing)
{
    LowMemory memory;
    bsp::MpConfiguration c;
    EXPECT_EQ(bsp::findMpConfiguration(memory, c).error, MpError::NotFound);
    memory.hole(0, 0x100000);
    EXPECT_EQ(bsp::findMpConfiguration(memory, c).error, MpError::NotFound);
    EXPECT_EQ(bsp::parseMpConfiguration(memory, kRomPointer, c).error, MpError::NotFound);
}

TEST(MpTable, ADamagedPointerIsReportedWhenNoGoodOneFollows)
{
    LowMemory memory = withRomTable(seabiosTable());
    memory.at(kRomPointer + 4) ^= 0x01; // The table address, without fixing the checksum.
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    EXPECT_EQ(result.error, MpError::PointerChecksum);
    EXPECT_EQ(result.address, kRomPointer);
    EXPECT_EQ(bsp::parseMpConfiguration(memory, kRomPointer, c).error, MpError::PointerChecksum);

    // "_MP_" met by chance before the real pointer is passed over.
    memory.place(0xFA000, floatingPointer(kRomTable));
    EXPECT_EQ(bsp::findMpConfiguration(memory, c).error, MpError::None);
    EXPECT_EQ(c.floatingPointerAddress, 0xFA000u);
}

TEST(MpTable, PointerLengthOtherThanOneParagraphIsRefused)
{
    LowMemory memory = withRomTable(seabiosTable());
    memory.place(kRomPointer, floatingPointer(kRomTable, 4, 0, 0, 2));
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    EXPECT_EQ(result.error, MpError::PointerLength);
    EXPECT_EQ(result.address, kRomPointer);
}

TEST(MpTable, PointerRevisionMustBe1Point1Or1Point4)
{
    for (const uint8_t revision : {0, 2, 3, 5}) {
        LowMemory memory = withRomTable(seabiosTable());
        memory.place(kRomPointer, floatingPointer(kRomTable, revision));
        bsp::MpConfiguration c;
        EXPECT_EQ(bsp::findMpConfiguration(memory, c).error, MpError::PointerRevision) << int(revision);
    }
    LowMemory memory = withRomTable(seabiosTable());
    memory.place(kRomPointer, floatingPointer(kRomTable, 1));
    bsp::MpConfiguration c;
    EXPECT_EQ(bsp::findMpConfiguration(memory, c).error, MpError::None);
}

TEST(MpTable, ADefaultConfigurationIsAnError)
{
    LowMemory memory;
    memory.place(kRomPointer, floatingPointer(0, 4, 5, 0x80));
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    EXPECT_EQ(result.error, MpError::DefaultConfiguration);
    EXPECT_EQ(result.address, kRomPointer);
    EXPECT_EQ(c.defaultConfiguration, 5);
    EXPECT_TRUE(c.imcrPresent);
}

TEST(MpTable, TheImcrPresentBitIsReported)
{
    LowMemory memory = withRomTable(seabiosTable());
    memory.place(kRomPointer, floatingPointer(kRomTable, 4, 0, 0x80));
    bsp::MpConfiguration c;
    ASSERT_EQ(bsp::findMpConfiguration(memory, c).error, MpError::None);
    EXPECT_TRUE(c.imcrPresent);
}

TEST(MpTable, ATableOutsideReadableMemoryIsUnreadable)
{
    bsp::MpConfiguration c;
    {
        LowMemory memory;
        memory.place(kRomPointer, floatingPointer(0x200000));
        const bsp::MpResult result = bsp::parseMpConfiguration(memory, kRomPointer, c);
        EXPECT_EQ(result.error, MpError::TableUnreadable);
        EXPECT_EQ(result.address, 0x200000u);
    }
    {
        // The header is readable, the entries are not.
        LowMemory memory = withRomTable(seabiosTable());
        memory.hole(kRomTable + 60, kRomTable + 61);
        EXPECT_EQ(bsp::parseMpConfiguration(memory, kRomPointer, c).error, MpError::TableUnreadable);
    }
    {
        // The table's stated end lies past the end of memory (and 4 GiB).
        LowMemory memory;
        memory.place(kRomPointer, floatingPointer(0xFFFFFFE0u));
        EXPECT_EQ(bsp::parseMpConfiguration(memory, kRomPointer, c).error, MpError::TableUnreadable);
        TableBuilder t = seabiosTable();
        const std::vector<uint8_t> bytes = t.build();
        memory.place(0xFFF00, std::vector<uint8_t>(bytes.begin(), bytes.begin() + 0x100));
        memory.place(kRomPointer, floatingPointer(0xFFF00));
        EXPECT_EQ(bsp::parseMpConfiguration(memory, kRomPointer, c).error, MpError::TableUnreadable);
    }
}

TEST(MpTable, TheTableMustStartWithPcmp)
{
    LowMemory memory = withRomTable(seabiosTable());
    memory.at(kRomTable + 3) = 'X';
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    EXPECT_EQ(result.error, MpError::TableSignature);
    EXPECT_EQ(result.address, kRomTable);
}

TEST(MpTable, AWrongTableChecksumIsRefused)
{
    LowMemory memory = withRomTable(seabiosTable());
    memory.at(kRomTable + 44 + 1) ^= 0x01; // The BSP's APIC id.
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::findMpConfiguration(memory, c);
    EXPECT_EQ(result.error, MpError::TableChecksum);
    EXPECT_EQ(result.address, kRomTable);
}

TEST(MpTable, TableRevisionMustBe1Point1Or1Point4)
{
    TableBuilder t = seabiosTable();
    t.revision = 2;
    EXPECT_EQ(parseTable(t), MpError::TableRevision);
    t.revision = 1;
    EXPECT_EQ(parseTable(t), MpError::None);
}

TEST(MpTable, TableLengthBelowTheHeaderOrOver64KibIsRefused)
{
    TableBuilder t = seabiosTable();
    t.baseLengthOverride = 43;
    t.entryCountOverride = 0;
    EXPECT_EQ(parseTable(t), MpError::TableLength);

    // Base and extended together above 64 KiB; nothing past the header is read.
    LowMemory memory;
    std::vector<uint8_t> header = TableBuilder().build();
    put16(header, 4, 0xFFF0);
    put16(header, 40, 0x0100);
    memory.place(kRomTable, header);
    memory.place(kRomPointer, floatingPointer(kRomTable));
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::parseMpConfiguration(memory, kRomPointer, c);
    EXPECT_EQ(result.error, MpError::TableLength);
    EXPECT_EQ(result.address, kRomTable);
}

TEST(MpTable, EntriesRunningPastTheBaseLengthAreTruncated)
{
    // The count names one entry more than the length holds.
    TableBuilder t = seabiosTable();
    t.entryCountOverride = 2 + 2 + 1 + 2 + 15 + 2 + 1;
    const LowMemory memory = withRomTable(t);
    bsp::MpConfiguration c;
    const bsp::MpResult result = bsp::parseMpConfiguration(memory, kRomPointer, c);
    EXPECT_EQ(result.error, MpError::EntryTruncated);
    EXPECT_EQ(result.address, kRomTable + uint32_t(t.build().size()));

    // A processor entry (20 bytes) that the length cuts at 8.
    TableBuilder cut;
    cut.processor(0, kEnabled | kBootstrap);
    cut.baseLengthOverride = 44 + 8;
    EXPECT_EQ(parseTable(cut), MpError::EntryTruncated);
}

TEST(MpTable, BytesAfterTheLastEntryAreTolerated)
{
    TableBuilder t = seabiosTable();
    t.entryCountOverride = 2 + 2 + 1 + 2 + 15 + 2 - 1; // The last local interrupt becomes padding.
    bsp::MpConfiguration c;
    EXPECT_EQ(parseTable(t, c), MpError::None);
    EXPECT_EQ(c.localInterruptCount, 1u);
}

TEST(MpTable, UnknownEntryTypesInterruptTypesAndFlagsAreRefused)
{
    TableBuilder t = seabiosTable();
    t.raw({5, 0, 0, 0, 0, 0, 0, 0});
    bsp::MpConfiguration c;
    const LowMemory memory = withRomTable(t);
    const bsp::MpResult result = bsp::parseMpConfiguration(memory, kRomPointer, c);
    EXPECT_EQ(result.error, MpError::UnknownEntry);
    EXPECT_EQ(result.address, kRomTable + uint32_t(t.build().size()) - 8);

    TableBuilder extendedType = seabiosTable();
    extendedType.raw({128, 8, 0, 0, 0, 0, 0, 0}); // An extended entry in the base table.
    EXPECT_EQ(parseTable(extendedType), MpError::UnknownEntry);

    TableBuilder interruptType = seabiosTable();
    interruptType.ioInterrupt(4, kConforming, kIsaBus, 2, kIoApicId, 2);
    EXPECT_EQ(parseTable(interruptType), MpError::UnknownEntry);

    TableBuilder polarity = seabiosTable();
    polarity.ioInterrupt(0, 0x2, kIsaBus, 2, kIoApicId, 2); // PO = 10, reserved.
    EXPECT_EQ(parseTable(polarity), MpError::UnknownEntry);

    TableBuilder trigger = seabiosTable();
    trigger.localInterrupt(1, 0x8, kIsaBus, 0, 1, 1); // EL = 10, reserved.
    EXPECT_EQ(parseTable(trigger), MpError::UnknownEntry);
}

TEST(MpTable, MoreProcessorsThanThereIsRoomForAreAnError)
{
    TableBuilder t = seabiosTable();
    for (uint8_t id = 2; id < bsp::MpConfiguration::kMaximumProcessors; ++id) {
        t.processor(id, kEnabled);
    }
    bsp::MpConfiguration c;
    EXPECT_EQ(parseTable(t, c), MpError::None);
    EXPECT_EQ(c.processorCount, bsp::MpConfiguration::kMaximumProcessors);
    t.processor(8, kEnabled);
    EXPECT_EQ(parseTable(t, c), MpError::TooManyProcessors);
    EXPECT_EQ(c.processorCount, bsp::MpConfiguration::kMaximumProcessors);
}

TEST(MpTable, MoreBusesThanThereIsRoomForAreAnError)
{
    TableBuilder t = seabiosTable();
    for (uint8_t id = 2; id < bsp::MpConfiguration::kMaximumBuses; ++id) {
        t.bus(id, "PCI   ");
    }
    EXPECT_EQ(parseTable(t), MpError::None);
    t.bus(16, "PCI   ");
    EXPECT_EQ(parseTable(t), MpError::TooManyBuses);
}

TEST(MpTable, MoreIoApicsThanThereIsRoomForAreAnError)
{
    TableBuilder t = seabiosTable();
    t.ioApic(3, 1, 0xFEC01000);
    bsp::MpConfiguration c;
    EXPECT_EQ(parseTable(t, c), MpError::None);
    EXPECT_EQ(c.ioApic(3)->address, 0xFEC01000u);
    t.ioApic(4, 1, 0xFEC02000);
    EXPECT_EQ(parseTable(t), MpError::TooManyIoApics);
}

TEST(MpTable, MoreInterruptsThanThereIsRoomForAreAnError)
{
    TableBuilder t = seabiosTable(); // 17 I/O interrupts.
    for (unsigned i = 17; i < bsp::MpConfiguration::kMaximumInterrupts; ++i) {
        t.ioInterrupt(0, kConforming, kPciBus, uint8_t(i), kIoApicId, 16 + i % 8);
    }
    EXPECT_EQ(parseTable(t), MpError::None);
    t.ioInterrupt(0, kConforming, kPciBus, 100, kIoApicId, 23);
    EXPECT_EQ(parseTable(t), MpError::TooManyInterrupts);

    TableBuilder local = seabiosTable(); // 2 local interrupts.
    for (unsigned i = 2; i < bsp::MpConfiguration::kMaximumLocalInterrupts; ++i) {
        local.localInterrupt(1, kConforming, kIsaBus, 0, uint8_t(i), 1);
    }
    EXPECT_EQ(parseTable(local), MpError::None);
    local.localInterrupt(1, kConforming, kIsaBus, 0, 0xFF, 1);
    EXPECT_EQ(parseTable(local), MpError::TooManyInterrupts);
}

TEST(MpTable, ExactlyOneEnabledBootstrapProcessorIsRequired)
{
    TableBuilder none;
    none.processor(0, kEnabled);
    none.processor(1, kEnabled);
    none.ioApic(kIoApicId);
    bsp::MpConfiguration c;
    const LowMemory memory = withRomTable(none);
    const bsp::MpResult result = bsp::parseMpConfiguration(memory, kRomPointer, c);
    EXPECT_EQ(result.error, MpError::NoBootProcessor);
    EXPECT_EQ(result.address, kRomTable);
    EXPECT_EQ(c.bootstrapProcessor(), nullptr);

    TableBuilder disabled;
    disabled.processor(0, kBootstrap);
    disabled.ioApic(kIoApicId);
    EXPECT_EQ(parseTable(disabled), MpError::NoBootProcessor);

    TableBuilder two;
    two.processor(0, kEnabled | kBootstrap);
    two.processor(1, kEnabled | kBootstrap);
    two.ioApic(kIoApicId);
    EXPECT_EQ(parseTable(two), MpError::NoBootProcessor);
}

TEST(MpTable, AnEnabledIoApicIsRequired)
{
    TableBuilder none;
    none.processor(0, kEnabled | kBootstrap);
    EXPECT_EQ(parseTable(none), MpError::NoIoApic);

    TableBuilder disabled;
    disabled.processor(0, kEnabled | kBootstrap);
    disabled.ioApic(kIoApicId, 0);
    bsp::MpConfiguration c;
    EXPECT_EQ(parseTable(disabled, c), MpError::NoIoApic);
    ASSERT_EQ(c.ioApicCount, 1u);
    EXPECT_FALSE(c.ioApics[0].enabled);
}

TEST(MpTable, DisabledProcessorsAreKeptAsDisabled)
{
    TableBuilder t;
    t.processor(0, kEnabled | kBootstrap);
    t.processor(1, 0);
    t.processor(2, kEnabled);
    t.ioApic(kIoApicId);
    bsp::MpConfiguration c;
    ASSERT_EQ(parseTable(t, c), MpError::None);
    ASSERT_EQ(c.processorCount, 3u);
    EXPECT_FALSE(c.processors[1].enabled);
    EXPECT_EQ(c.processors[1].apicId, 1);
    EXPECT_TRUE(c.processors[2].enabled);
}

TEST(MpTable, IsaRoutesResolveConformingToHighAndEdge)
{
    bsp::MpConfiguration c;
    ASSERT_EQ(parseTable(seabiosTable(), c), MpError::None);
    bsp::IoApicRoute route{};
    ASSERT_TRUE(c.isaRoute(0, route)); // The timer arrives at pin 2.
    EXPECT_EQ(route.ioApicId, kIoApicId);
    EXPECT_EQ(route.pin, 2);
    EXPECT_FALSE(route.activeLow);
    EXPECT_FALSE(route.levelTriggered);
    for (uint8_t irq = 1; irq < 16; ++irq) {
        if (irq == 2) {
            EXPECT_FALSE(c.isaRoute(irq, route)); // SeaBIOS lists no IRQ 2.
            continue;
        }
        ASSERT_TRUE(c.isaRoute(irq, route)) << int(irq);
        EXPECT_EQ(route.pin, irq);
    }
    EXPECT_FALSE(c.isaRoute(16, route));
}

TEST(MpTable, IsaRoutesKeepExplicitPolarityAndTrigger)
{
    bsp::MpConfiguration c;
    ASSERT_EQ(parseTable(seabiosTable(), c), MpError::None);
    bsp::IoApicRoute route{};
    ASSERT_TRUE(c.isaRoute(9, route));
    EXPECT_FALSE(route.activeLow);
    EXPECT_TRUE(route.levelTriggered);
    ASSERT_TRUE(c.isaRoute(14, route));
    EXPECT_TRUE(route.activeLow);
    EXPECT_FALSE(route.levelTriggered);
}

TEST(MpTable, PciRoutesResolveConformingToLowAndLevel)
{
    bsp::MpConfiguration c;
    ASSERT_EQ(parseTable(seabiosTable(), c), MpError::None);
    bsp::IoApicRoute route{};
    ASSERT_TRUE(c.pciRoute(kPciBus, 1, 0, route));
    EXPECT_EQ(route.ioApicId, kIoApicId);
    EXPECT_EQ(route.pin, 11);
    EXPECT_TRUE(route.activeLow);
    EXPECT_TRUE(route.levelTriggered);
    ASSERT_TRUE(c.pciRoute(kPciBus, 3, 0, route)); // Explicitly high and edge.
    EXPECT_EQ(route.pin, 10);
    EXPECT_FALSE(route.activeLow);
    EXPECT_FALSE(route.levelTriggered);
    EXPECT_FALSE(c.pciRoute(kPciBus, 1, 1, route)); // INTB# is not listed.
    EXPECT_FALSE(c.pciRoute(kPciBus, 2, 0, route));
    EXPECT_FALSE(c.pciRoute(kPciBus, 32, 0, route));
    EXPECT_FALSE(c.pciRoute(kPciBus, 1, 4, route));
    // Source IRQ 4 on the ISA bus is IRQ 4, not PCI device 1's INTA#.
    EXPECT_FALSE(c.pciRoute(kIsaBus, 1, 0, route));
}

TEST(MpTable, ExplicitLowLevelAndTheAllIoApicsDestinationResolve)
{
    TableBuilder t;
    t.processor(0, kEnabled | kBootstrap);
    t.bus(0, "ISA   ");
    t.bus(1, "EISA  ");
    t.bus(2, "PCI\0\0\0");
    t.ioApic(5);
    t.ioInterrupt(0, kLowLevel, 0, 7, 0xFF, 7);
    t.ioInterrupt(0, kHighEdge, 2, (4 << 2) | 3, 5, 19);
    bsp::MpConfiguration c;
    ASSERT_EQ(parseTable(t, c), MpError::None);
    EXPECT_EQ(c.bus(1)->kind, bsp::MpBusKind::Eisa);
    EXPECT_EQ(c.bus(2)->kind, bsp::MpBusKind::Pci); // NUL padding is accepted.
    bsp::IoApicRoute route{};
    ASSERT_TRUE(c.isaRoute(7, route));
    EXPECT_EQ(route.ioApicId, 5);
    EXPECT_TRUE(route.activeLow);
    EXPECT_TRUE(route.levelTriggered);
    ASSERT_TRUE(c.pciRoute(2, 4, 3, route));
    EXPECT_EQ(route.pin, 19);
    EXPECT_FALSE(route.activeLow);
    EXPECT_FALSE(route.levelTriggered);
}

TEST(MpTable, OtherBusesAndNonIntTypesAreNotIsaRoutes)
{
    TableBuilder t;
    t.processor(0, kEnabled | kBootstrap);
    t.bus(0, "MCA   ");
    t.bus(1, "ISA   ");
    t.ioApic(kIoApicId);
    t.ioInterrupt(0, kConforming, 0, 3, kIoApicId, 3);   // From the MCA bus.
    t.ioInterrupt(3, kConforming, 1, 0, kIoApicId, 0);   // ExtINT from the ISA bus.
    t.ioInterrupt(0, kConforming, 9, 4, kIoApicId, 4);   // From a bus the table does not list.
    bsp::MpConfiguration c;
    ASSERT_EQ(parseTable(t, c), MpError::None);
    EXPECT_EQ(c.bus(0)->kind, bsp::MpBusKind::Other);
    bsp::IoApicRoute route{};
    EXPECT_FALSE(c.isaRoute(3, route));
    EXPECT_FALSE(c.isaRoute(0, route));
    EXPECT_FALSE(c.isaRoute(4, route));
}

TEST(MpTable, TheExtendedTableChecksumIsChecked)
{
    TableBuilder t = seabiosTable();
    t.extended = {128, 20, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}; // A system address space entry.
    t.extended[2] = 0x12;
    bsp::MpConfiguration c;
    EXPECT_EQ(parseTable(t, c), MpError::None);

    LowMemory memory = withRomTable(t);
    const uint32_t extendedAt = kRomTable + uint32_t(t.build().size() - t.extended.size());
    memory.at(extendedAt + 5) = 0x77;
    const bsp::MpResult result = bsp::parseMpConfiguration(memory, kRomPointer, c);
    EXPECT_EQ(result.error, MpError::TableChecksum);
    EXPECT_EQ(result.address, extendedAt);

    // Beyond readable memory.
    memory.hole(extendedAt + 10, extendedAt + 11);
    EXPECT_EQ(bsp::parseMpConfiguration(memory, kRomPointer, c).error, MpError::TableUnreadable);
}

TEST(MpTable, IdentificationStringsArePrintable)
{
    TableBuilder t = seabiosTable();
    t.oem = std::string("OEM\x01\x7F", 5);
    t.product = std::string("P\0Q", 3);
    bsp::MpConfiguration c;
    ASSERT_EQ(parseTable(t, c), MpError::None);
    EXPECT_STREQ(c.oemId, "OEM??");
    EXPECT_STREQ(c.productId, "P?Q");
}

TEST(MpTable, ParsingStartsFromAnEmptyConfiguration)
{
    bsp::MpConfiguration c;
    ASSERT_EQ(parseTable(seabiosTable(), c), MpError::None);
    LowMemory empty;
    EXPECT_EQ(bsp::parseMpConfiguration(empty, kRomPointer, c).error, MpError::NotFound);
    EXPECT_EQ(c.processorCount, 0u);
    EXPECT_EQ(c.interruptCount, 0u);
}

TEST(MpTable, EveryErrorHasItsOwnText)
{
    std::set<std::string> texts;
    for (int e = int(MpError::None); e <= int(MpError::NoIoApic); ++e) {
        const char* text = bsp::mpErrorText(MpError(e));
        ASSERT_NE(text, nullptr);
        EXPECT_GT(std::strlen(text), 10u);
        texts.insert(text);
    }
    EXPECT_EQ(texts.size(), size_t(MpError::NoIoApic) + 1);
    EXPECT_STREQ(bsp::mpErrorText(MpError::TableChecksum), "the MP configuration table's checksum is wrong");
}

} // namespace
