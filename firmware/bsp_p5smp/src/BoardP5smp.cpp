// Board support for the dual-Pentium controller (seed 9.2, controller nodes
// 2 and 3; Fig. 9.2): two Pentium processors with their local APICs, an I/O
// APIC, the MultiProcessor Specification 1.4 tables the BIOS leaves, and the
// PC/AT peripherals (PcPeripherals.cpp) on its ISA bus.
//
// This node runs on the bootstrap processor. Its tick is its own local
// APIC's timer, calibrated against the 8254; the ISA lines reach it through
// the I/O APIC, routed as the MP table says, while the 8259A pair is masked
// and, where the board has the IMCR, cut off (MP spec 3.6.2.1). Lines keep
// their PC/AT numbers, so the kernel, the drivers and the applications see
// the same lines on both boards; line 0 is the local APIC timer instead of
// the 8254, and line 2, the 8259A's cascade input on a PC/AT, is the
// inter-processor interrupt the other node of the board raises.
#include <bsp/Board.hpp>
#include <bsp/IoApic.hpp>
#include <bsp/LocalApic.hpp>
#include <bsp/MpTable.hpp>
#include <bsp/P5smpBoard.hpp>
#include <bsp/PcPeripherals.hpp>
#include <bsp/Pic8259.hpp>
#include <bsp/ApTrampoline.h>
#include <bsp/SecondProcessor.hpp>
#include <bsp/SharedMemoryLink.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/Gdt.hpp>
#include <arch_x86/Idt.hpp>
#include <arch_x86/Paging.hpp>
#include <arch_x86/PortIo.hpp>
#include <boot/Panic.hpp>

#include <runtime/Format.hpp>

#include <string.h>

extern "C" {
// ApicSpurious.S: the local APIC's spurious vector, which takes no EOI.
void apicSpuriousEntry();
uint32_t apicSpuriousCount = 0;
// Node 3's kernel image, stripped, which node 2's images carry as data
// (mk/board_p5smp.mk). Weak: node 3's own image carries none.
[[gnu::weak]] extern const uint8_t _binary_node3_stripped_elf_start[];
[[gnu::weak]] extern const uint8_t _binary_node3_stripped_elf_end[];
}

namespace bsp {

uint32_t apicTickCounts = 0;
uint32_t apicNanosecondsPerCountQ24 = 0;

namespace {

// PC/AT ports the board still uses: the 8259A pair (to mask it), the 8254's
// counter 2 and its gate and output on port 0x61 (to calibrate the APIC
// timer), and the IMCR (MP spec 3.6.2.1).
constexpr uint16_t masterPicPort = 0x20;
constexpr uint16_t slavePicPort = 0xA0;
constexpr uint16_t pitCounter2Port = 0x42;
constexpr uint16_t pitControlPort = 0x43;
constexpr uint16_t systemControlPortB = 0x61;
constexpr uint16_t imcrSelectPort = 0x22;
constexpr uint16_t imcrDataPort = 0x23;
// Port B (PC/AT technical reference): bit 0 gates counter 2, bit 1 drives
// the speaker from it, bit 5 reads counter 2's output.
constexpr uint8_t portBCounter2Gate = 1u << 0;
constexpr uint8_t portBSpeakerData = 1u << 1;
constexpr uint8_t portBCounter2Output = 1u << 5;
// 8254 control word (Intel 8254 datasheet, "Control Word Format"): counter
// 2, low byte then high byte, mode 0 (interrupt on terminal count), binary.
constexpr uint8_t pitCounter2Mode0 = 0xB0;
// The IMCR's register and its value that routes the 8259A's INTR to the
// APIC instead of the processor (MP spec 3.6.2.1).
constexpr uint8_t imcrRegister = 0x70;
constexpr uint8_t imcrApicMode = 0x01;

constexpr uint32_t pitHz = 1'193'182;
// 50 ms of the 8254: short at boot, long enough that the poll's few
// instructions and the 8254's own step (838 ns) are under 20 ppm.
constexpr uint16_t calibrationCounts = 59'659;
// At least ten times as many reads of port B as 50 ms can take on a 150 MHz
// Pentium, so only an 8254 that never counts ends the wait.
constexpr uint32_t calibrationPolls = 50'000'000;
constexpr LocalApic::TimerDivide timerDivide = LocalApic::TimerDivide::By16;

// The vectors: the lines from firstIrqVector, as on the ISA board, and the
// spurious vector, whose low four bits must be set on the Pentium's APIC
// (SDM Vol. 3A, 11.9).
constexpr uint8_t spuriousVector = 0xFF;
constexpr uint8_t vectorOf(unsigned line) { return static_cast<uint8_t>(arch_x86::firstIrqVector + line); }
static_assert(systemTickLine == 0 && interProcessorLine == 2);
static_assert(vectorOf(systemTickLine) == 32, "BoardTick.hpp reads the tick's request as bit 0 of IRR 32-63");

// An inter-processor interrupt's wait for its delivery status, in reads.
constexpr uint32_t deliverySpins = 100'000;

// What node 3 owns when it runs (seed 9.2: devices are assigned to the
// nodes asymmetrically): its console, COM4 at 0x2E8 on IRQ 7, and IRQs 12
// and 13, which nothing on the board drives (the PS/2 mouse port is unused,
// and the FPU reports its errors as exceptions, CR0.NE), as its spare
// lines, besides its own tick and the inter-processor interrupt line every
// node has. Node 2
// owns every other ISA line, and it alone programs the I/O APIC: its
// select and window registers are one pair that two processors cannot
// share without a lock, so node 3's lines are routed to it once, at its
// start, unmasked, and node 3 masks them in software.
constexpr uint16_t node3ConsolePort = 0x2E8;
constexpr unsigned node3ConsoleLine = 7;
constexpr unsigned node3SpareLines[2] = {12, 13};
constexpr unsigned node2SpareLines[2] = {5, 11};
constexpr uint16_t node3Lines = (1u << node3ConsoleLine) | (1u << node3SpareLines[0]) | (1u << node3SpareLines[1]);
// How long node 2 waits for the second processor to report from protected mode.
constexpr uint32_t answerMicroseconds = 100'000;

LocalApic localApic(arch_x86::IoWindow::memory(LocalApic::kDefaultBase, LocalApic::kWindowBytes));
IoApic ioApic(arch_x86::IoWindow::memory(IoApic::kDefaultBase, IoApic::kWindowBytes));
Pic8259 pic(arch_x86::IoWindow::ports(masterPicPort, 2), arch_x86::IoWindow::ports(slavePicPort, 2));

MpConfiguration mp;
bool mpValid = false;
MpResult mpResult{MpError::NotFound, 0};

struct Attachment {
    InterruptHandler handler;
    void* context;
};
// What each line's owner attached, and what the dispatch calls: the same,
// but for the tick while the kernel masks it (see applyMask()).
Attachment registered[interruptLineCount];
Attachment attachments[interruptLineCount];

// Where each ISA line arrives at the I/O APIC; line 0 and line 2 are the
// local APIC's own (timer and inter-processor interrupt), never routed.
struct LineRoute {
    bool routed;
    uint8_t pin;
    bool activeLow;
    bool levelTriggered;
};
LineRoute routes[interruptLineCount];

uint32_t unexpected[interruptLineCount];
uint16_t maskedLines = 0xFFFF; // Lines without a handler, or masked by the kernel.
uint16_t overlayLines = 0;     // Lines held off by the running task's interrupt level.
// Lines masked here rather than at their source (see applyMask()), and
// those of them that interrupted while masked.
uint16_t softwareMaskedLines = 1u << systemTickLine;
uint16_t pendingLines = 0;
// The lines this node may attach: every one but another node's.
uint16_t ownedLines = 0xFFFF;
bool isNode3 = false;
bool node3Running = false;
// The other node's APIC id and node id (node 3 has them from the MP table and node 2).
uint8_t otherApicId = 0xFF;
uint16_t otherNode = 3;
uint16_t node = 2;
uint32_t tickRate = defaultTickRateHz;
uint64_t tickPeriodNs = 0;
uint64_t apicTimerHz = 0;

const BoardIdentity board{"p5smp", "Pentium"};

// Low memory for the MP table search. Page 0 is not mapped (Paging.hpp),
// so the BIOS data area's two words the search reads are answered from
// what the loader reported: no EBDA pointer, which sends the search to the
// last KiB of base memory (where a BIOS keeps its EBDA), and the base
// memory size. Everything else below 1 MiB is read where it lies.
class LowMemory final : public PhysicalMemory {
public:
    explicit LowMemory(uint32_t baseMemoryKib) : baseMemoryKib_(baseMemoryKib) {}

    bool read(uint32_t address, void* into, uint32_t bytes) const override
    {
        constexpr uint32_t ebdaSegmentWord = 0x40E;
        constexpr uint32_t baseMemoryWord = 0x413;
        constexpr uint32_t lowMemoryEnd = 0x100000;
        if (bytes == 2 && (address == ebdaSegmentWord || address == baseMemoryWord)) {
            const uint16_t value = address == ebdaSegmentWord ? 0 : static_cast<uint16_t>(baseMemoryKib_);
            memcpy(into, &value, sizeof value);
            return true;
        }
        if (address < arch_x86::Paging::kPageSize || address >= lowMemoryEnd || bytes > lowMemoryEnd - address) {
            return false;
        }
        memcpy(into, reinterpret_cast<const void*>(static_cast<uintptr_t>(address)), bytes);
        return true;
    }

private:
    uint32_t baseMemoryKib_;
};

uint8_t bootstrapApicId() { return localApic.id(); }

// The tick's line is the timer's LVT entry: its mask bit holds the tick off.
void setTimerMasked(bool masked)
{
    const arch_x86::IoWindow& registers = localApic.window();
    const uint32_t entry = registers.read32(LocalApic::kLvtTimer);
    registers.write32(LocalApic::kLvtTimer, masked ? entry | LocalApic::kLvtMask : entry & ~LocalApic::kLvtMask);
}

// An interrupt raised again on @p line's vector, by this processor to itself.
void raiseAgain(unsigned line) { (void)localApic.sendFixed(localApic.id(), vectorOf(line), deliverySpins); }

// Applies the mask of @p line: masked without a handler, by the kernel, or
// by the running task's level. An ISA line of node 2 is masked at the I/O
// APIC. The tick is not: a masked LVT entry drops the timer's interrupts
// (SDM Vol. 3A, 11.5.1), where the 8259A holds a masked request until the
// unmask, and the kernel counts on that. Nor are node 3's lines, which only
// node 2 programs. Those are masked in software: while the line's owner is
// attached its interrupts keep coming, one that comes while the line is
// masked is only noted, and the unmask raises it again. Line 2, the other
// processor's interrupts, cannot be held off at its source and keeps no mask.
void applyMask(unsigned line)
{
    const bool masked = ((maskedLines | overlayLines) >> line & 1u) != 0;
    if ((softwareMaskedLines >> line & 1u) != 0) {
        const bool attached = registered[line].handler != nullptr;
        if (line == systemTickLine) {
            setTimerMasked(!attached);
        }
        attachments[line] = masked ? Attachment{nullptr, nullptr} : registered[line];
        const uint16_t bit = static_cast<uint16_t>(1u << line);
        if (attached && !masked && (pendingLines & bit) != 0) {
            pendingLines = static_cast<uint16_t>(pendingLines & ~bit);
            raiseAgain(line);
        }
    } else if ((ownedLines >> line & 1u) != 0 && routes[line].routed) {
        (void)ioApic.setMasked(routes[line].pin, masked);
    }
}

[[gnu::noinline]] void dispatchUncommon(unsigned line)
{
    if ((softwareMaskedLines >> line & 1u) != 0 && registered[line].handler != nullptr) {
        pendingLines = static_cast<uint16_t>(pendingLines | (1u << line)); // Delivered on the unmask.
        localApic.endOfInterrupt();
        return;
    }
    // Nobody owns this line: mask it so it cannot storm, and count it.
    ++unexpected[line];
    maskedLines = static_cast<uint16_t>(maskedLines | (1u << line));
    applyMask(line);
    localApic.endOfInterrupt();
}

void dispatchInterrupt(unsigned line)
{
    const Attachment& attachment = attachments[line];
    if (attachment.handler == nullptr) [[unlikely]] {
        dispatchUncommon(line);
        return;
    }
    // The local APIC holds back this vector's priority class and every
    // lower one until the EOI below (SDM Vol. 3A, 11.8.3): enabling
    // interrupts lets only more urgent classes nest.
    arch_x86::enableInterrupts();
    attachment.handler(attachment.context);
    arch_x86::disableInterrupts();
    localApic.endOfInterrupt();
}

// The processor must have a local APIC (CPUID.1:EDX bit 9): the board's
// interrupts all pass through it.
bool processorHasApic()
{
    uint32_t eax = 1;
    uint32_t ebx;
    uint32_t ecx = 0;
    uint32_t edx;
    asm volatile("cpuid" : "+a"(eax), "=b"(ebx), "+c"(ecx), "=d"(edx));
    constexpr uint32_t cpuidApic = 1u << 9;
    return (edx & cpuidApic) != 0;
}

// Counts of the APIC timer in calibrationCounts of the 8254's counter 2,
// as Hz; 0 when the 8254 never reached its terminal count.
uint64_t measureApicTimerHz()
{
    const uint8_t portB = arch_x86::portRead8(systemControlPortB);
    // The gate high and the speaker off; in mode 0 the count starts with
    // the write of its high byte, which comes right after the APIC's start.
    arch_x86::portWrite8(systemControlPortB,
                         static_cast<uint8_t>((portB & ~portBSpeakerData) | portBCounter2Gate));
    arch_x86::portWrite8(pitControlPort, pitCounter2Mode0);
    arch_x86::portWrite8(pitCounter2Port, static_cast<uint8_t>(calibrationCounts & 0xFF));
    // A one-shot from the largest count ends after minutes: it raises
    // nothing before stopTimer() below, and interrupts are off anyway.
    (void)localApic.startOneShot(vectorOf(systemTickLine), 0xFFFFFFFFu, timerDivide);
    arch_x86::portWrite8(pitCounter2Port, static_cast<uint8_t>(calibrationCounts >> 8));
    uint32_t polls = 0;
    while ((arch_x86::portRead8(systemControlPortB) & portBCounter2Output) == 0 && ++polls < calibrationPolls) {
    }
    const uint32_t elapsed = 0xFFFFFFFFu - localApic.currentCount();
    localApic.stopTimer();
    arch_x86::portWrite8(systemControlPortB, portB);
    if (polls >= calibrationPolls) {
        return 0;
    }
    return (uint64_t{elapsed} * pitHz + calibrationCounts / 2) / calibrationCounts;
}

// Masks the 8259A pair for good (vectors remapped above the exceptions
// first, so a stray request cannot pass for one) and, where the board has
// the IMCR, disconnects it from the processor.
void retirePics()
{
    pic.initialise(static_cast<uint8_t>(arch_x86::firstIrqVector));
    for (unsigned line = 0; line < Pic8259::lineCount; ++line) {
        pic.mask(line);
    }
    if (mpValid && mp.imcrPresent) {
        arch_x86::portWrite8(imcrSelectPort, imcrRegister);
        arch_x86::portWrite8(imcrDataPort, imcrApicMode);
    }
}

// The MP table's routes of the ISA lines, or the MP spec's default
// configuration's (5.3: IRQ 0 on INTIN2, the others on their own pin).
// Where each ISA line arrives: the MP table's route, or the MP spec's
// default configuration's (5.3: IRQ 0 on INTIN2, the others on their own pin).
void findRoutes()
{
    for (unsigned line = 0; line < interruptLineCount; ++line) {
        routes[line] = LineRoute{};
        if (line == systemTickLine || line == interProcessorLine) {
            continue;
        }
        IoApicRoute route{};
        if (mpValid && mp.isaRoute(static_cast<uint8_t>(line), route)) {
            if (route.pin < ioApic.pinCount()) {
                routes[line] = {true, route.pin, route.activeLow, route.levelTriggered};
            }
        } else {
            // A line the table does not name is on its own pin, edge
            // triggered and active high, as in the default configurations.
            // A BIOS leaves out the IRQs it keeps for PCI (SeaBIOS leaves
            // out 5, 9, 10 and 11), yet an ISA card set to one of them
            // drives that pin all the same. (A PCI device steered onto one
            // of them would drive it low and level: its MP table entry,
            // MpConfiguration::pciRoute, says so.)
            routes[line] = {true, static_cast<uint8_t>(line), false, false};
        }
    }
}

// Node 2 routes every line with an I/O APIC pin: @p lines to the processor
// with APIC id @p destination, the others masked to itself.
void routeLines(uint16_t lines, uint8_t destination, bool masked)
{
    for (unsigned line = 0; line < interruptLineCount; ++line) {
        const LineRoute& route = routes[line];
        if (route.routed && (lines >> line & 1u) != 0) {
            (void)ioApic.route(route.pin, vectorOf(line), destination, route.activeLow, route.levelTriggered, masked);
        }
    }
}

// The second processor of the MP table: the first enabled one that is not
// the bootstrap processor; 0xFF when there is none.
uint8_t secondProcessorApicId()
{
    if (!mpValid) {
        return 0xFF;
    }
    const uint8_t bootstrap = mp.bootstrapProcessor()->apicId;
    for (unsigned i = 0; i < mp.processorCount; ++i) {
        if (mp.processors[i].enabled && mp.processors[i].apicId != bootstrap) {
            return mp.processors[i].apicId;
        }
    }
    return 0xFF;
}

// A busy wait on the local APIC timer, before the tick starts: a one-shot
// count, masked so that its end raises nothing, and polled.
void delayMicroseconds(uint32_t microseconds)
{
    const uint32_t counts = static_cast<uint32_t>(apicTimerHz * microseconds / 1'000'000u) + 1;
    (void)localApic.startOneShot(vectorOf(systemTickLine), counts, timerDivide);
    setTimerMasked(true);
    // A count is 16 bus clocks (timerDivide), and a poll takes at least one
    // processor clock, never shorter than a bus clock: a live timer ends
    // within 16 polls a count. The bound only guards a dead timer.
    const uint64_t pollLimit = uint64_t{counts} * 16 + 16;
    for (uint64_t polls = 0; localApic.currentCount() != 0 && polls <= pollLimit; ++polls) {
    }
}

// Node 3's command line: its node id, the APIC timer's rate node 2 measured
// (it cannot use the 8254, which is node 2's), and every option of node 2's
// command line written "node3.<option>", without that prefix.
char node3CommandLine[AP_TRAMPOLINE_COMMAND_LINE_BYTES];

void composeNode3CommandLine(const char* node2CommandLine)
{
    runtime::BufferSink out(node3CommandLine, sizeof node3CommandLine);
    runtime::format(out, "node=3 peer=%u apic_hz=%lu", unsigned(node), static_cast<unsigned long>(apicTimerHz));
    constexpr char prefix[] = "node3.";
    constexpr size_t prefixLength = sizeof prefix - 1;
    for (const char* word = node2CommandLine; *word != '\0';) {
        while (*word == ' ') {
            ++word;
        }
        const char* end = word;
        while (*end != '\0' && *end != ' ') {
            ++end;
        }
        if (static_cast<size_t>(end - word) > prefixLength && memcmp(word, prefix, prefixLength) == 0) {
            out.put(' ');
            for (const char* c = word + prefixLength; c != end; ++c) {
                out.put(*c);
            }
        }
        word = end;
    }
}

// Starts node 3 on the second processor, its lines routed to it first so
// that none of its interrupts can reach node 2 once it runs; if it does not
// start they come back, masked, to node 2.
void startNode3(const boot::BootInfo& bootInfo)
{
    const uint8_t node3ApicId = secondProcessorApicId();
    runtime::CharacterSink& out = pc::consoleUart();
    if (node3ApicId == 0xFF) {
        runtime::format(out, "one processor: node 3 is not started\r\n");
        return;
    }
    const uint8_t* image = _binary_node3_stripped_elf_start;
    const size_t bytes = image != nullptr ? static_cast<size_t>(_binary_node3_stripped_elf_end - image) : 0;
    const uint32_t memoryEnd = 0x100000u + bootInfo.upperMemoryKib * 1024u;
    // Node 2's image and the page tables after it (a page per 4 MiB mapped,
    // and the directory) must end below node 3's half.
    const uintptr_t node2End = boot::imageLayout().end + (memoryEnd / 0x400000u + 2) * arch_x86::Paging::kPageSize;
    if (node2End > SecondProcessor::kNodeBase) {
        runtime::format(out, "node 3 is not started: node 2's image ends at 0x%lx, above node 3's half at 0x%lx\r\n",
                        static_cast<unsigned long>(node2End), static_cast<unsigned long>(SecondProcessor::kNodeBase));
        return;
    }
    uint32_t entry = 0;
    SecondProcessor::Outcome node3Outcome = SecondProcessor::load(image, bytes, memoryEnd, entry);
    if (node3Outcome == SecondProcessor::Outcome::Started) {
        composeNode3CommandLine(bootInfo.commandLine);
        SharedMemoryArea::at().layOut();
        routeLines(node3Lines, node3ApicId, false);
        const SecondProcessor::Launch launch{entry, node3ApicId, bootInfo.lowerMemoryKib, bootInfo.upperMemoryKib,
                                             node3CommandLine, delayMicroseconds};
        node3Outcome = SecondProcessor::start(localApic, launch, answerMicroseconds);
    }
    if (node3Outcome != SecondProcessor::Outcome::Started) {
        routeLines(node3Lines, bootstrapApicId(), true);
        runtime::format(out, "node 3 is not started on the processor with APIC id %u: %s\r\n", unsigned(node3ApicId),
                        SecondProcessor::describe(node3Outcome));
        return;
    }
    ownedLines = static_cast<uint16_t>(ownedLines & ~node3Lines);
    node3Running = true;
    otherApicId = node3ApicId;
    runtime::format(out, "node 3 started on the processor with APIC id %u (image at 0x%lx, %lu bytes; console COM4)\r\n",
                    unsigned(node3ApicId), static_cast<unsigned long>(SecondProcessor::kNodeBase),
                    static_cast<unsigned long>(bytes));
}

void reportConfiguration()
{
    runtime::CharacterSink& out = pc::consoleUart();
    if (!mpValid) {
        runtime::format(out,
                        "warning: MP configuration not used: %s (at 0x%lx); the default configuration is assumed "
                        "(local APIC at 0x%lx, I/O APIC at 0x%lx, ISA IRQ 0 on pin 2, the others on their own), "
                        "and no second processor is started\r\n",
                        mpErrorText(mpResult.error), static_cast<unsigned long>(mpResult.address),
                        static_cast<unsigned long>(LocalApic::kDefaultBase),
                        static_cast<unsigned long>(IoApic::kDefaultBase));
        return;
    }
    const MpProcessor* bootstrap = mp.bootstrapProcessor();
    runtime::format(out, "MP 1.%u table at 0x%lx (%s %s): %u processors, bootstrap APIC %u;",
                    unsigned(mp.specRevision), static_cast<unsigned long>(mp.tableAddress), mp.oemId,
                    mp.productId, mp.processorCount, unsigned(bootstrap->apicId));
    for (unsigned i = 0; i < mp.ioApicCount; ++i) {
        runtime::format(out, " I/O APIC %u at 0x%lx%s", unsigned(mp.ioApics[i].id),
                        static_cast<unsigned long>(mp.ioApics[i].address), mp.ioApics[i].enabled ? "" : " (disabled)");
    }
    runtime::format(out, " (%u pins)\r\n", ioApic.pinCount());
}

} // namespace

const BoardIdentity& identity() { return board; }

void initialise(const boot::BootInfo& bootInfo, uint32_t tickRateHz)
{
    if (!processorHasApic()) {
        dcosPanic("the processor has no local APIC: this image is for the dual-Pentium board (p5smp)");
    }
    // BoardTick.hpp and the windows above read the APICs at their default
    // bases, which every board of this design keeps; a table saying
    // otherwise (checked below) describes another board.
    if (!arch_x86::Paging::mapDevice(LocalApic::kDefaultBase, LocalApic::kWindowBytes) ||
        !arch_x86::Paging::mapDevice(IoApic::kDefaultBase, IoApic::kWindowBytes)) {
        dcosPanic("cannot map the APICs' registers");
    }
    const LowMemory lowMemory(bootInfo.lowerMemoryKib);
    mpResult = findMpConfiguration(lowMemory, mp);
    mpValid = mpResult.error == MpError::None;
    // Node 3 is the node that does not run on the bootstrap processor.
    isNode3 = mpValid && localApic.id() != mp.bootstrapProcessor()->apicId;
    node = pc::nodeFromCommandLine(bootInfo, isNode3 ? 3 : 2);
    const uint32_t localApicBase = mpValid ? mp.localApicAddress : LocalApic::kDefaultBase;
    // The first enabled I/O APIC: the parser requires one, not that it comes first.
    const MpIoApic* firstIoApic = nullptr;
    for (unsigned i = 0; mpValid && i < mp.ioApicCount && firstIoApic == nullptr; ++i) {
        firstIoApic = mp.ioApics[i].enabled ? &mp.ioApics[i] : nullptr;
    }
    const uint32_t ioApicBase = firstIoApic != nullptr ? firstIoApic->address : IoApic::kDefaultBase;
    if (localApicBase != LocalApic::kDefaultBase || ioApicBase != IoApic::kDefaultBase) {
        dcosPanic("the MP table puts the local APIC at 0x%lx and the I/O APIC at 0x%lx, not at 0x%lx and 0x%lx "
                  "where this board keeps them",
                  static_cast<unsigned long>(localApicBase), static_cast<unsigned long>(ioApicBase),
                  static_cast<unsigned long>(LocalApic::kDefaultBase), static_cast<unsigned long>(IoApic::kDefaultBase));
    }

    arch_x86::Idt::setInterruptHandler(dispatchInterrupt);
    arch_x86::Idt::setGate(spuriousVector, arch_x86::Gdt::kernelCode,
                           static_cast<uint32_t>(reinterpret_cast<uintptr_t>(&apicSpuriousEntry)), 0x8E);
    if (!localApic.enable(spuriousVector)) {
        dcosPanic("the local APIC refused spurious vector 0x%x", unsigned(spuriousVector));
    }
    findRoutes();
    tickRate = pc::tickRateFromCommandLine(bootInfo, tickRateHz);
    if (isNode3) {
        // Node 2 routed node 3's lines to it and keeps the rest, the 8254
        // and the real-time clock: node 3 masks its lines in software and
        // takes the APIC timer's rate from node 2.
        ownedLines = static_cast<uint16_t>(node3Lines | (1u << systemTickLine) | (1u << interProcessorLine));
        softwareMaskedLines = static_cast<uint16_t>(softwareMaskedLines | node3Lines);
        pc::leaveRealTimeClock();
        pc::initialiseConsole(node3ConsolePort, node3ConsoleLine);
        char text[16];
        uint32_t hz = 0;
        if (!boot::findCommandLineOption(bootInfo.commandLine, "apic_hz", text, sizeof text) ||
            !pc::decimalOption(text, 10, hz) || hz == 0) {
            dcosPanic("node 3 needs the APIC timer's rate from node 2 (apic_hz= on its command line)");
        }
        apicTimerHz = hz;
        otherApicId = mp.bootstrapProcessor()->apicId;
        uint32_t peer = 0;
        otherNode = boot::findCommandLineOption(bootInfo.commandLine, "peer", text, sizeof text) &&
                            pc::decimalOption(text, 5, peer) && peer >= 1 && peer <= 0xFFFE
                        ? static_cast<uint16_t>(peer)
                        : 2;
        runtime::format(pc::consoleUart(), "node 3 on the processor with APIC id %u; local APIC timer %lu Hz (from node 2)\r\n",
                        unsigned(localApic.id()), static_cast<unsigned long>(apicTimerHz));
    } else {
        retirePics();
        ioApic.maskAll();
        routeLines(0xFFFF, bootstrapApicId(), true);
        pc::initialiseConsole();
        reportConfiguration();
        apicTimerHz = measureApicTimerHz();
        if (apicTimerHz == 0) {
            dcosPanic("the 8254's counter 2 never reached its terminal count: the local APIC timer cannot be "
                      "calibrated");
        }
    }
    const uint32_t counts = static_cast<uint32_t>((apicTimerHz + tickRate / 2) / tickRate);
    tickPeriodNs = (uint64_t{counts} * 1'000'000'000u + apicTimerHz / 2) / apicTimerHz;
    apicNanosecondsPerCountQ24 =
        static_cast<uint32_t>(((uint64_t{1'000'000'000u} << 24) + apicTimerHz / 2) / apicTimerHz);
    const uint32_t shortenBy = pc::crystalShortening(bootInfo, counts);
    if (!isNode3) {
        runtime::format(pc::consoleUart(), "local APIC timer %lu Hz (against the 8254), %lu counts per tick\r\n",
                        static_cast<unsigned long>(apicTimerHz), static_cast<unsigned long>(counts));
        if (mpValid) {
            startNode3(bootInfo);
        }
    }
    // The timer counts counts - shortenBy per period: with a crystal model
    // the clock's reading within a tick runs over those, and the tick itself
    // still counts as the nominal period, so the clock runs fast.
    apicTickCounts = counts - shortenBy;
    // Started masked: attachInterrupt(systemTickLine) unmasks it.
    if (apicTickCounts < 2 || !localApic.startPeriodic(vectorOf(systemTickLine), apicTickCounts - 1, timerDivide)) {
        dcosPanic("the local APIC timer cannot tick at %lu Hz from %lu Hz", static_cast<unsigned long>(tickRate),
                  static_cast<unsigned long>(apicTimerHz));
    }
    setTimerMasked(true);
}

dcos::Status attachInterrupt(unsigned line, InterruptHandler handler, void* context)
{
    if (line >= interruptLineCount || handler == nullptr) {
        return dcos::Status::InvalidArgument;
    }
    if ((ownedLines >> line & 1u) == 0) {
        return dcos::Status::InvalidArgument; // The other node of the board owns this line.
    }
    if (line != systemTickLine && line != interProcessorLine && !routes[line].routed) {
        return dcos::Status::InvalidArgument; // The MP table routes this ISA line nowhere.
    }
    arch_x86::InterruptGuard guard;
    if (registered[line].handler != nullptr) {
        return dcos::Status::Busy;
    }
    registered[line] = {handler, context};
    attachments[line] = registered[line];
    maskedLines = static_cast<uint16_t>(maskedLines & ~(1u << line));
    applyMask(line);
    return dcos::Status::Ok;
}

dcos::Status detachInterrupt(unsigned line)
{
    if (line >= interruptLineCount) {
        return dcos::Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    maskedLines = static_cast<uint16_t>(maskedLines | (1u << line));
    registered[line] = {nullptr, nullptr};
    attachments[line] = {nullptr, nullptr};
    pendingLines = static_cast<uint16_t>(pendingLines & ~(1u << line));
    applyMask(line);
    return dcos::Status::Ok;
}

void maskInterrupt(unsigned line)
{
    if (line >= interruptLineCount) {
        return;
    }
    arch_x86::InterruptGuard guard;
    maskedLines = static_cast<uint16_t>(maskedLines | (1u << line));
    applyMask(line);
}

void unmaskInterrupt(unsigned line)
{
    if (line >= interruptLineCount) {
        return;
    }
    arch_x86::InterruptGuard guard;
    maskedLines = static_cast<uint16_t>(maskedLines & ~(1u << line));
    applyMask(line);
}

bool isInterruptMasked(unsigned line) { return line < interruptLineCount && ((maskedLines >> line) & 1u) != 0; }

bool isInterruptRequested(unsigned line)
{
    arch_x86::InterruptGuard guard;
    return line < interruptLineCount && (localApic.isRequested(vectorOf(line)) || (pendingLines >> line & 1u) != 0);
}

uint16_t interruptLinesHeldOff()
{
    arch_x86::InterruptGuard guard;
    uint16_t held = 0;
    for (unsigned line = 0; line < interruptLineCount; ++line) {
        // Another node's line cannot interrupt this one at all.
        bool off = true;
        if ((ownedLines >> line & 1u) == 0) {
            off = true;
        } else if ((softwareMaskedLines >> line & 1u) != 0) {
            off = attachments[line].handler == nullptr;
        } else if (routes[line].routed) {
            off = ioApic.isMasked(routes[line].pin);
        } else {
            off = false; // Line 2: nothing holds it off.
        }
        held = static_cast<uint16_t>(held | (off ? 1u << line : 0u));
    }
    return held;
}

bool interruptCutShort(unsigned& line)
{
    arch_x86::InterruptGuard guard;
    for (unsigned candidate = 0; candidate < interruptLineCount; ++candidate) {
        if (localApic.isInService(vectorOf(candidate))) {
            line = candidate;
            return true;
        }
    }
    return false;
}

unsigned spareInterruptLine(unsigned which)
{
    return (isNode3 ? node3SpareLines : node2SpareLines)[which != 0 ? 1 : 0];
}

bool ownsPciBus() { return !isNode3; }

dcos::Status routePciInterrupt(uint8_t bus, uint8_t device, uint8_t pin, unsigned line)
{
    if (isNode3) {
        return dcos::Status::NotSupported; // Node 2 owns the bus and the I/O APIC.
    }
    if (line >= interruptLineCount || line == systemTickLine || line == interProcessorLine ||
        (ownedLines >> line & 1u) == 0) {
        return dcos::Status::InvalidArgument;
    }
    // Only the MP table knows where a PCI pin arrives: the default
    // configurations have no PCI bus (MP spec 5.1).
    IoApicRoute route{};
    if (!mpValid || !mp.pciRoute(bus, device, pin, route) || route.pin >= ioApic.pinCount()) {
        return dcos::Status::NotFound;
    }
    arch_x86::InterruptGuard guard;
    if (registered[line].handler != nullptr) {
        return dcos::Status::Busy;
    }
    // One pin, one line: another line taken to be on that pin (an ISA line
    // the table does not name, which findRoutes() put on its own pin) is
    // routed nowhere now, since the pin is the device's.
    for (unsigned other = 0; other < interruptLineCount; ++other) {
        if (other != line && routes[other].routed && routes[other].pin == route.pin) {
            if (registered[other].handler != nullptr) {
                return dcos::Status::Busy;
            }
            routes[other] = LineRoute{};
        }
    }
    if (routes[line].routed && routes[line].pin != route.pin) {
        (void)ioApic.setMasked(routes[line].pin, true); // The line's old pin now carries nothing of it.
    }
    routes[line] = {true, route.pin, route.activeLow, route.levelTriggered};
    // Masked until a handler is attached (applyMask() unmasks it then).
    (void)ioApic.route(route.pin, vectorOf(line), bootstrapApicId(), route.activeLow, route.levelTriggered, true);
    return dcos::Status::Ok;
}

uint32_t unexpectedInterruptCount(unsigned line) { return line < interruptLineCount ? unexpected[line] : 0; }

uint32_t spuriousInterruptCount() { return apicSpuriousCount; }

uint32_t tickRateHz() { return tickRate; }

uint64_t tickPeriodNanoseconds() { return tickPeriodNs; }

void setTaskInterruptLevel(uint8_t level)
{
    const uint16_t overlay = pc::linesAtOrBelowLevel(level);
    if (overlay == overlayLines) {
        return; // The common case: the same level as the task before.
    }
    const uint16_t changed = static_cast<uint16_t>(overlay ^ overlayLines);
    overlayLines = overlay;
    for (unsigned line = 0; line < interruptLineCount; ++line) {
        if ((changed >> line & 1u) != 0) {
            applyMask(line);
        }
    }
}

uint16_t nodeId() { return node; }

unsigned processorIndex() { return isNode3 ? 1 : 0; }

bool otherNodeRunning() { return isNode3 || node3Running; }

uint16_t otherNodeId() { return otherNode; }

bool signalOtherNode()
{
    return otherNodeRunning() && localApic.sendFixed(otherApicId, vectorOf(interProcessorLine), deliverySpins);
}

} // namespace bsp
