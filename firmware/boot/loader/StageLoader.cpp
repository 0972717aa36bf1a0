// The stage loader (docs/boot.md, "How a controller starts"): the program
// the card's boot sector starts, before any kernel. It reads the card's
// configuration and boot state, decides with BootPlanner which slot's image
// boots, checks that image's signature and digest with the same verifier the
// host tools use (firmware/image, mbedTLS), loads it, and starts it as a
// Multiboot loader would, so the kernel starts the same way from the card
// as from QEMU's -kernel. A new image boots as a trial with the board's
// watchdog armed: if it does not confirm, the watchdog resets the board and
// the next boot reverts.
//
// Everything runs with interrupts off and polls: the console on COM1, the
// card by ATA PIO (drivers/ata). Every message starts with "stage: ", so a
// test or an engineer tells it from the kernel's.
#include <ata/AtaPioDisk.hpp>
#include <boot/AtaSectorStore.hpp>
#include <boot/BootInfo.hpp>
#include <boot/BootSequence.hpp>
#include <boot/BootState.hpp>
#include <boot/CardLayout.hpp>
#include <boot/Multiboot.hpp>
#include <boot/TrialWatchdog.hpp>
#include <boot/ConfigurationBlock.hpp>
#include <bsp/BoardReset.hpp>
#include <bsp/RecoveryStrap.hpp>
#include <flash/CanFlashServer.hpp>
#include <flash/FlashSession.hpp>
#include <flash/SerialFramer.hpp>
#include <image/ImageVerifier.hpp>

#include <arch_x86/PortIo.hpp>
#include <can/MessageIdentifier.hpp>
#include <dcos/Version.hpp>
#include <sja1000/BitTiming.hpp>
#include <sja1000/IsaCardSettings.hpp>
#include <sja1000/Sja1000Chip.hpp>
#include <runtime/Format.hpp>

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

namespace {

using arch_x86::portRead8;
using arch_x86::portWrite8;
namespace card = boot::card;

// -- the console: COM1, polled ------------------------------------------------

// The 16550's ports (PC/AT COM1) and the line status bit that says the
// transmitter holds no character (16550D data sheet, LSR bit 5, THRE).
constexpr uint16_t kCom1 = 0x3F8;
constexpr uint16_t kCom1InterruptEnable = kCom1 + 1;
constexpr uint16_t kCom1FifoControl = kCom1 + 2;
constexpr uint16_t kCom1LineControl = kCom1 + 3;
constexpr uint16_t kCom1ModemControl = kCom1 + 4;
constexpr uint16_t kCom1LineStatus = kCom1 + 5;
constexpr uint8_t kDataReady = 0x01;        // LSR bit 0, DR
constexpr uint8_t kTransmitterEmpty = 0x20; // LSR bit 5, THRE
constexpr uint8_t kTransmitterIdle = 0x40;  // LSR bit 6, TEMT: the last stop bit has left

// 115200 bit/s 8N1, FIFOs on, no interrupts: what the kernel's console
// uses too, so one terminal sees both (16550D data sheet, Tables 2 to 4).
void setUpConsole()
{
    portWrite8(kCom1InterruptEnable, 0x00);
    portWrite8(kCom1LineControl, 0x80); // DLAB
    portWrite8(kCom1 + 0, 0x01);        // divisor 1: 115200 bit/s from 1.8432 MHz
    portWrite8(kCom1 + 1, 0x00);
    portWrite8(kCom1LineControl, 0x03); // 8 data bits, no parity, 1 stop bit
    portWrite8(kCom1FifoControl, 0x07); // FIFOs on and cleared
    portWrite8(kCom1ModemControl, 0x03); // DTR, RTS
}

class StageConsole final : public runtime::CharacterSink {
public:
    void put(char character) override
    {
        // Bounded: a UART that never empties (none fitted) does not hang the boot.
        for (unsigned poll = 0; poll < 100000 && (portRead8(kCom1LineStatus) & kTransmitterEmpty) == 0; ++poll) {
        }
        portWrite8(kCom1, static_cast<uint8_t>(character));
    }
};

StageConsole console;

// One line on the console: the prefix, the formatted text, CR LF.
void sayLine(const char* prefix, const char* format, va_list arguments)
{
    runtime::format(console, "%s", prefix);
    runtime::formatTo(console, format, arguments);
    runtime::format(console, "\r\n");
}

__attribute__((format(printf, 1, 2))) void say(const char* format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    sayLine("stage: ", format, arguments);
    va_end(arguments);
}

[[noreturn]] void halt()
{
    for (;;) {
        asm volatile("cli; hlt");
    }
}

// -- the machine ----------------------------------------------------------------

// The MC146818's CMOS RAM (ports 0x70/0x71): bytes 0x30 and 0x31 hold the
// memory above 1 MiB in KiB, as the BIOS counted it (IBM PC/AT Technical
// Reference, "CMOS RAM address map"). Bit 7 of the index port is the NMI
// mask, left set here.
uint32_t extendedMemoryKib()
{
    portWrite8(0x70, 0x80 | 0x30);
    const uint32_t low = portRead8(0x71);
    portWrite8(0x70, 0x80 | 0x31);
    const uint32_t high = portRead8(0x71);
    return low | (high << 8);
}

// True when addresses above 1 MiB are not folded onto the first megabyte.
bool a20Enabled()
{
    volatile uint32_t* low = reinterpret_cast<volatile uint32_t*>(0x7E00);
    volatile uint32_t* high = reinterpret_cast<volatile uint32_t*>(0x107E00);
    const uint32_t saved = *low;
    *low = 0x0D0C05A2u;
    *high = ~0x0D0C05A2u;
    const bool enabled = *low == 0x0D0C05A2u;
    *low = saved;
    return enabled;
}

// The boot sector asked the BIOS; if that did not work, the "fast A20"
// bit of system control port A (0x92, bit 1), which PC/AT-compatible
// chipsets have.
bool enableA20()
{
    if (a20Enabled()) {
        return true;
    }
    portWrite8(0x92, static_cast<uint8_t>((portRead8(0x92) | 0x02) & ~0x01));
    return a20Enabled();
}

// -- the card ---------------------------------------------------------------------

alignas(4) uint8_t sectorA[card::kSectorSize];
alignas(4) uint8_t sectorB[card::kSectorSize];

bool readRecordCopies(ata::AtaPioDisk& disk, uint32_t lba)
{
    const ata::AtaError first = disk.read(lba, 1, sectorA);
    const ata::AtaError second = disk.read(lba + 1, 1, sectorB);
    if (first != ata::AtaError::Ok || second != ata::AtaError::Ok) {
        say("cannot read sectors %lu and %lu: %s", static_cast<unsigned long>(lba),
            static_cast<unsigned long>(lba + 1),
            ata::ataErrorText(first != ata::AtaError::Ok ? first : second));
        return false;
    }
    return true;
}

boot::ConfigurationBlock configuration;
image::TrustedKey trustedKeys[boot::ConfigurationBlock::kMaximumKeys];
size_t trustedKeyCount = 0;

// The verdict of the last slot loaded into memory, whose image is then in
// place at its load address.
uint8_t loadedSlot = boot::BootState::kNoSlot;
image::ImageHeader loadedHeader;

// Reads a slot's image into its place in memory and checks it: the header
// (signature, board, memory window) first, then the payload's digest. The
// card keeps the 256-byte header in the slot's first sector and the
// payload from its second, so that the payload's sectors are read straight
// to where the image runs.
bool loadAndVerify(ata::AtaPioDisk& disk, uint8_t slot, uint32_t memoryEnd)
{
    loadedSlot = boot::BootState::kNoSlot;
    const uint32_t lba = card::kSlotLba[slot];
    const ata::AtaError header = disk.read(lba, 1, sectorA);
    if (header != ata::AtaError::Ok) {
        say("slot %s: cannot read: %s", card::slotName(slot), ata::ataErrorText(header));
        return false;
    }
    const image::ImageResult<image::ImageHeader> decoded = image::ImageHeader::decode(sectorA, sizeof sectorA);
    if (!decoded.ok()) {
        say("slot %s: %s", card::slotName(slot), image::imageErrorText(decoded.error()));
        return false;
    }
    image::ImagePolicy policy = image::ImagePolicy::forBoard(image::BoardType::Isa486);
    if (memoryEnd < policy.memoryEnd) {
        policy.memoryEnd = memoryEnd;
    }
    const image::ImageResult<image::ImageHeader> checked = image::ImageVerifier::checkHeader(
        sectorA, image::ImageHeader::kSize, uint64_t{image::ImageHeader::kSize} + decoded.value().payloadSize,
        trustedKeys, trustedKeyCount, policy);
    if (!checked.ok()) {
        say("slot %s: %s", card::slotName(slot), image::imageErrorText(checked.error()));
        return false;
    }
    const image::ImageHeader& image = checked.value();
    auto* place = reinterpret_cast<uint8_t*>(static_cast<uintptr_t>(image.loadAddress));
    const uint32_t whole = image.payloadSize / card::kSectorSize;
    const uint32_t tail = image.payloadSize % card::kSectorSize;
    ata::AtaError read = whole != 0 ? disk.read(lba + 1, whole, place) : ata::AtaError::Ok;
    if (read == ata::AtaError::Ok && tail != 0) {
        // The last part sector through a buffer: no byte past the payload is written.
        read = disk.read(lba + 1 + whole, 1, sectorB);
        for (uint32_t i = 0; read == ata::AtaError::Ok && i < tail; ++i) {
            place[whole * card::kSectorSize + i] = sectorB[i];
        }
    }
    if (read != ata::AtaError::Ok) {
        say("slot %s: cannot read the payload: %s", card::slotName(slot), ata::ataErrorText(read));
        return false;
    }
    const image::ImageError payload = image::ImageVerifier::checkPayload(image, place, image.payloadSize);
    char version[32];
    image.version.format(version, sizeof version);
    if (payload != image::ImageError::Ok) {
        say("slot %s: %s %s: %s", card::slotName(slot), image::boardName(image.board), version,
            image::imageErrorText(payload));
        return false;
    }
    say("slot %s: %s %s, signature and digest valid", card::slotName(slot), image::boardName(image.board), version);
    loadedSlot = slot;
    loadedHeader = image;
    return true;
}

// -- the hand-over ------------------------------------------------------------------

boot::multiboot::Info handover;
// The configuration's line, "node=65535 can0=1000000 " before it and the
// boot's facts (a 31-character version at most) after it.
char commandLine[boot::ConfigurationBlock::kCommandLineSize + 128];
const char loaderName[] = "DCOS stage loader";

[[noreturn]] void start(const image::ImageHeader& image, uint8_t slot, bool trial, bool reverted, uint32_t upperKib)
{
    // The memory after the payload that the image's .bss needs zeroed.
    auto* place = reinterpret_cast<uint8_t*>(static_cast<uintptr_t>(image.loadAddress));
    for (uint32_t i = image.payloadSize; i < image.memorySize; ++i) {
        place[i] = 0;
    }
    char version[32];
    image.version.format(version, sizeof version);
    // The kernel learns where it came from on its command line: the
    // configuration's own line, then the boot's facts (docs/boot.md).
    // The configuration's node id reaches the kernel as "node=", and its
    // CAN bit rate as "can0=", which brings can0 up on the network at boot.
    // They come before the configuration's own line, so they win over the
    // same options there (the kernel takes an option's first word): a node
    // id or bit rate changed over the bus (docs/protocols/config.md) takes
    // effect whatever the line a card was made with says.
    char nodeText[16] = {};
    char rateText[20] = {};
    if (configuration.nodeId != 0) {
        runtime::formatToBuffer(nodeText, sizeof nodeText, "node=%u ", static_cast<unsigned>(configuration.nodeId));
    }
    if (configuration.canBitRate != 0) {
        runtime::formatToBuffer(rateText, sizeof rateText, "can0=%lu ",
                                static_cast<unsigned long>(configuration.canBitRate));
    }
    runtime::formatToBuffer(commandLine, sizeof commandLine, "%s%s%s%sboot.slot=%s boot.version=%s%s%s", nodeText,
                            rateText, configuration.commandLine, configuration.commandLine[0] != '\0' ? " " : "",
                            card::slotName(slot), version, trial ? " boot.trial=1" : "",
                            reverted ? " boot.reverted=1" : "");
    handover.flags = boot::multiboot::kInfoMemory | boot::multiboot::kInfoCommandLine | boot::multiboot::kInfoLoaderName;
    handover.memLower = 640;
    handover.memUpper = upperKib;
    handover.cmdline = reinterpret_cast<uintptr_t>(commandLine);
    handover.bootLoaderName = reinterpret_cast<uintptr_t>(loaderName);
    if (trial) {
        boot::watchdog::armForTrial();
        say("watchdog armed: the new image must confirm within %u s", boot::watchdog::kTrialSeconds);
    } else {
        boot::watchdog::stop();
    }
    say("starting slot %s at 0x%08lx", card::slotName(slot), static_cast<unsigned long>(image.entry));
    asm volatile("jmp *%2" : : "a"(boot::multiboot::kLoaderMagic), "b"(&handover), "r"(image.entry) : "memory");
    __builtin_unreachable();
}

// The node id, as the kernel will take it: the configuration's, else
// "node=" on the configuration's command line read by the kernel's own rule
// (boot::parseNodeId), else 1 (the kernel's default).
uint16_t nodeId()
{
    if (configuration.nodeId != 0) {
        return configuration.nodeId;
    }
    char text[8];
    uint16_t node = 1;
    if (boot::findCommandLineOption(configuration.commandLine, "node", text, sizeof text)) {
        (void)boot::parseNodeId(text, node);
    }
    return node;
}

// What makes this start's challenges its own: the real-time clock's time
// and date, the 8254's count, and the boot state's sequence. Not secret:
// the flash protocol's challenge only has to be new (docs/protocols/flash.md).
void challengeSeed(uint8_t (&seed)[12], uint32_t sequence)
{
    static constexpr uint8_t kClockRegisters[] = {0x00, 0x02, 0x04, 0x07, 0x08, 0x09};
    for (size_t i = 0; i < sizeof kClockRegisters; ++i) {
        portWrite8(0x70, static_cast<uint8_t>(0x80 | kClockRegisters[i]));
        seed[i] = portRead8(0x71);
    }
    portWrite8(0x43, 0x00); // latch counter 0
    seed[6] = portRead8(0x40);
    seed[7] = portRead8(0x40);
    for (int i = 0; i < 4; ++i) {
        seed[8 + i] = static_cast<uint8_t>(sequence >> (8 * i));
    }
}

// The real-time clock's seconds register (MC146818, register 0): it moves
// once a second, which is all the recovery loop needs of a clock.
uint8_t clockSecond()
{
    portWrite8(0x70, 0x80 | 0x00);
    return portRead8(0x71);
}

// Restarts the board once the console has sent its last character.
[[noreturn]] void resetBoard()
{
    for (unsigned poll = 0; poll < 100000 && (portRead8(kCom1LineStatus) & kTransmitterIdle) == 0; ++poll) {
    }
    bsp::resetBoard();
}

// -- CAN in recovery: the first channel of the board's CAN card, polled ----------

// The bit rate when the configuration names none: the kernel driver's.
constexpr uint32_t kDefaultCanBitRate = 125000;

class RecoveryCan {
public:
    RecoveryCan()
        : chip_(arch_x86::IoWindow::ports(sja1000::kIsaCardDefaultBase, sja1000::reg::kWindowSize))
    {
    }

    // Whether a chip answers and takes the bus at @p bitRate, taking every
    // extended frame (the server picks its own), with no interrupt.
    const char* start(uint32_t bitRate)
    {
        const dcos::Result<sja1000::BitTiming> timing = sja1000::BitTimingCalculator::forBitRate(bitRate);
        if (!timing.ok()) {
            return "the configuration's CAN bit rate cannot be made by the card";
        }
        if (chip_.probe() != dcos::Status::Ok) {
            return "no CAN card answers";
        }
        if (chip_.configure(timing.value(), sja1000::AcceptanceFilter::extended(0, 0), 0) != dcos::Status::Ok ||
            chip_.start(sja1000::BusMode::Normal) != dcos::Status::Ok) {
            return "the CAN card does not start";
        }
        return nullptr;
    }

    // The next frame received, if any.
    bool receive(can::CanFrame& frame)
    {
        if ((chip_.status() & sja1000::reg::kStatusReceiveBuffer) == 0) {
            return false;
        }
        const can::LinkResult<can::CanFrame> read = chip_.readReceiveBuffer();
        if (!read.ok()) {
            return false;
        }
        frame = read.value();
        return true;
    }

    // Queues @p frame; the caller waits for transmitted() before the next.
    void send(const can::CanFrame& frame)
    {
        // The transmit buffer is free: the last frame completed, or was
        // given up on below (transmitted() never has two in flight).
        chip_.writeTransmitBuffer(frame);
        chip_.transmit();
        pending_ = true;
    }

    // True once, when the frame sent last has left.
    bool transmitted()
    {
        if (!pending_ || (chip_.status() & sja1000::reg::kStatusTransmitComplete) == 0) {
            return false;
        }
        pending_ = false;
        return true;
    }

    // A frame nobody acknowledges is repeated by the chip for ever: the
    // caller gives up on it after its ISO-TP time-out, and so does the chip.
    void giveUp()
    {
        if (pending_) {
            chip_.abortTransmission();
            pending_ = false;
        }
    }

    bool pending() const { return pending_; }

private:
    sja1000::Sja1000Chip chip_;
    bool pending_ = false;
};

ata::AtaPioDisk* recoveryDisk = nullptr;
uint32_t recoveryMemoryEnd = 16u << 20;
uint32_t recoverySequence = 0;

// Recovery: the stage loader serves the flash protocol on COM1 (framed,
// so the console's text around it does not matter) and on the CAN card's
// first channel (ISO-TP, as CAN node number the configuration's node id)
// until a host has put a verified image on the card and asks for a
// restart, which boots it as a trial. One session serves both: a host uses
// either. Without a card or a trusted key there is nothing to serve.
//
// The only clock here is the real-time clock's seconds, so the ISO-TP
// time-outs run on whole seconds: a 1 s time-out ends between 1 and 2 s
// after its start, as the serial line's abandoned frame does.
[[noreturn]] void recovery(const char* why)
{
    say("recovery: %s", why);
    if (recoveryDisk == nullptr || trustedKeyCount == 0) {
        say("recovery: no card or no trusted key: halted");
        halt();
    }
    boot::AtaSectorStore store(*recoveryDisk);
    flash::SessionIdentity identity;
    identity.node = nodeId();
    identity.board = image::BoardType::Isa486;
    identity.mode = flash::NodeMode::Recovery;
    identity.memoryEnd = recoveryMemoryEnd;
    uint8_t seed[12];
    challengeSeed(seed, recoverySequence);
    // On the stack: this function never returns, and the boot sector's
    // stack below 0x90000 has room above the stage loader's memory.
    flash::FlashSession session(store, trustedKeys, trustedKeyCount, identity, seed, sizeof seed);
    flash::SerialFramer receiver;
    uint8_t reply[flash::kMaxMessage];
    uint8_t framed[flash::kMaxMessage + flash::SerialFramer::kOverhead];

    RecoveryCan bus;
    const uint32_t bitRate = configuration.canBitRate != 0 ? configuration.canBitRate : kDefaultCanBitRate;
    const bool nodeNumbered = identity.node <= can::MessageIdentifier::kMaxNodeNumber;
    const char* canProblem = nodeNumbered ? bus.start(bitRate) : "the node id is no CAN node number (1 to 254)";
    const bool onCan = canProblem == nullptr;
    flash::CanFlashServer server(session, static_cast<uint8_t>(identity.node));
    if (onCan) {
        say("recovery: waiting for an image on this serial line or on CAN as node %u at %lu bit/s (dcos-flash)",
            unsigned(identity.node), static_cast<unsigned long>(bitRate));
    } else {
        say("recovery: CAN not served: %s", canProblem);
        say("recovery: waiting for an image on this serial line (dcos-flash)");
    }

    // A frame left unfinished for two ticks of the real-time clock's
    // seconds (one to two seconds) is abandoned: its sender went away.
    uint8_t lastSecond = clockSecond();
    uint64_t seconds = 0;
    unsigned silentSeconds = 0;
    auto send = [&](const flash::CanFlashServer::Output& output) {
        if (output.transmit) {
            bus.send(output.frame);
        }
    };
    for (;;) {
        const uint64_t now = seconds * 1000000000ull;
        if (onCan) {
            can::CanFrame frame;
            if (bus.transmitted()) {
                send(server.onTransmitConfirmed(now));
            } else if (!bus.pending() && bus.receive(frame)) {
                send(server.onFrame(frame, now));
            } else if (bus.pending() && server.nextDeadlineNs() <= now) {
                bus.giveUp(); // Nobody takes it: the sender's N_As ends the reply.
                send(server.poll(now));
            } else if (!bus.pending() && server.nextDeadlineNs() <= now) {
                send(server.poll(now));
            }
            flash::RestartTarget target{};
            if (server.restartDue(target)) {
                resetBoard();
            }
        }
        if ((portRead8(kCom1LineStatus) & kDataReady) == 0) {
            const uint8_t second = clockSecond();
            if (second != lastSecond) {
                lastSecond = second;
                ++seconds;
                if (receiver.inFrame() && ++silentSeconds >= 2) {
                    receiver.reset();
                    silentSeconds = 0;
                }
            }
            continue;
        }
        silentSeconds = 0;
        if (!receiver.receive(portRead8(kCom1))) {
            continue;
        }
        const size_t length = session.handle(receiver.payload(), receiver.payloadLength(), reply, sizeof reply);
        const size_t frameLength = flash::SerialFramer::frame(reply, length, framed, sizeof framed);
        for (size_t i = 0; i < frameLength; ++i) {
            console.put(static_cast<char>(framed[i]));
        }
        flash::RestartTarget target{};
        if (session.restartRequested(target)) {
            resetBoard();
        }
    }
}

} // namespace

// The verifier's mbedTLS and the I/O windows report what cannot go on here.
extern "C" [[noreturn]] void dcosPanic(const char* format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    sayLine("stage: panic: ", format, arguments);
    va_end(arguments);
    halt();
}

extern "C" [[noreturn]] void stageMain(uint32_t bootDrive)
{
    setUpConsole();
    say("DCOS stage loader %s, from BIOS drive 0x%02lx", dcos::versionString, static_cast<unsigned long>(bootDrive));
    // The recovery strap is sampled once, as the board starts, as a strap
    // is: what the line does later does not change this start. It sends
    // the node into recovery whatever its card holds, so that an image
    // that hangs at boot, which no watchdog ends once it is confirmed, can
    // still be replaced (docs/guide/flashing.md).
    const bool strapped = bsp::recoveryStrapSet();
    if (strapped) {
        say("the recovery strap is set");
    }
    if (!enableA20()) {
        recovery("the A20 gate cannot be enabled: no memory above 1 MiB");
    }
    const uint32_t upperKib = extendedMemoryKib();
    const uint32_t memoryEnd = (1u << 20) + upperKib * 1024u;
    recoveryMemoryEnd = memoryEnd;

    ata::AtaPioDisk disk = ata::AtaPioDisk::primary();
    const ata::AtaError identified = disk.identify();
    if (identified != ata::AtaError::Ok) {
        recovery(ata::ataErrorText(identified));
    }
    say("card: %s, %lu sectors", disk.model(), static_cast<unsigned long>(disk.sectorCount()));
    recoveryDisk = &disk;
    if (disk.sectorCount() < card::kMinimumCardSectors) {
        recovery("the card is smaller than the layout needs");
    }

    unsigned copy = 0;
    if (!readRecordCopies(disk, card::kConfigurationLba) ||
        !boot::newestCopy(sectorA, sectorB, configuration, copy)) {
        recovery("no valid configuration on the card");
    }
    for (size_t i = 0; i < configuration.keyCount; ++i) {
        trustedKeys[trustedKeyCount++] = image::TrustedKey::fromPoint(configuration.keys[i]);
    }
    say("configuration %lu: %u trusted key%s", static_cast<unsigned long>(configuration.sequence),
        static_cast<unsigned>(trustedKeyCount), trustedKeyCount == 1 ? "" : "s");
    if (trustedKeyCount == 0) {
        recovery("the configuration trusts no key, so no image can be verified");
    }

    boot::AtaSectorStore store(disk);
    const boot::StoredBootState stored = boot::BootStateStore::read(store);
    if (stored.present) {
        const boot::BootState& state = stored.state;
        say("boot state %lu: confirmed slot %s, trial %s%s", static_cast<unsigned long>(state.sequence),
            card::slotName(state.confirmedSlot),
            state.trial == boot::TrialState::None      ? "none"
            : state.trial == boot::TrialState::Pending ? "pending in slot "
                                                       : "booting in slot ",
            state.trial == boot::TrialState::None ? "" : card::slotName(state.trialSlot));
    } else if (stored.readable) {
        say("no boot state on the card: a new card");
    }
    if (stored.present && stored.state.recoveryRequested) {
        // Once: the mark goes before recovery starts, so that a node whose
        // host went away boots its image again at the next reset.
        boot::BootState cleared = stored.state;
        cleared.recoveryRequested = false;
        recoverySequence = stored.state.sequence + 1;
        if (!boot::BootStateStore::writeNext(store, stored, cleared)) {
            recovery("asked to stay in recovery, and the boot state cannot be written");
        }
        recovery(strapped ? "the recovery strap is set, and a flash tool asked the node to stay in recovery"
                          : "a flash tool asked the node to stay in recovery");
    }
    if (strapped) {
        // Before any slot is loaded or the boot state changes: the card
        // stays as it is, and the next start without the strap boots what
        // it would have booted.
        recoverySequence = stored.present ? stored.state.sequence : 0;
        recovery("the recovery strap is set");
    }
    const boot::BootDecision decision = boot::BootSequence::decide(
        store, stored, [&](uint8_t slot) { return loadAndVerify(disk, slot, memoryEnd); });
    const boot::BootPlan& plan = decision.plan;
    recoverySequence = stored.present ? stored.state.sequence : 0;
    say("%s", plan.reason);
    if (decision.cardFailed) {
        recovery(plan.reason);
    }
    if (plan.action == boot::BootPlan::Action::Recovery) {
        recovery(plan.reason);
    }
    if (loadedSlot != plan.slot && !loadAndVerify(disk, plan.slot, memoryEnd)) {
        recovery("the chosen image did not verify when loaded again");
    }
    start(loadedHeader, plan.slot, plan.trial, plan.reverted, upperKib);
}
