// The emulator's two-channel ISA SJA1000 card (isa-sja1000), register by
// register, from the controller: raw port I/O in PeliCAN mode, no driver.
// The board file wires the card at 0x280 (channel 0) and 0x2A0 (channel 1),
// IRQ 10 and 11, with a 16 MHz crystal. Register names and sections
// ("DS 6.4.5") are those of the SJA1000 data sheet (Philips, 2000 Jan 04);
// bit timing, frame lengths and fault confinement follow the lab bus
// timing model (docs/protocols/labbus.md).
//
// The DCOS_TARGET_TESTs run on one board whose card has no hub: each
// channel is then a chip alone on its bus, whose frames nobody
// acknowledges. They check reset values and access rules, the lone node's
// ACK errors up to error passive, self test, bus-off and its recovery,
// listen-only mode and both interrupt lines, with the exact emulated
// timing of each.
//
// The `canlab` console command drives a channel from an emulator test
// (tests_renode/test_can_bus.py) with several boards on a lab bus: it
// configures a channel, sends frames (at an absolute uptime if asked, so
// that boards start together), echoes frames, and prints what its
// interrupt routine recorded, with the uptime of each event.
#include "KernelTestSupport.hpp"

#include <dcos/SystemAgent.hpp>
#include <dcos/TimerAgent.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/PortIo.hpp>
#include <runtime/Text.hpp>
#include <shell/ShellCommand.hpp>

namespace target_test {

namespace {

using dcos::Status;
using dcos::systemAgent;
using dcos::taskAgent;
using dcos::timerAgent;

// -- the card ------------------------------------------------------------------

constexpr unsigned kChannels = 2;
constexpr uint16_t kCardBase = 0x280;
constexpr uint16_t kChannelPorts = 0x20;
constexpr unsigned kLines[kChannels] = {10, 11};

// PeliCAN registers (DS 6.4.1, Table 7).
constexpr uint8_t kMod = 0;
constexpr uint8_t kCmr = 1;
constexpr uint8_t kSr = 2;
constexpr uint8_t kIr = 3;
constexpr uint8_t kIer = 4;
constexpr uint8_t kBtr0 = 6;
constexpr uint8_t kBtr1 = 7;
constexpr uint8_t kOcr = 8;
constexpr uint8_t kAlc = 11;
constexpr uint8_t kEcc = 12;
constexpr uint8_t kEwlr = 13;
constexpr uint8_t kRxerr = 14;
constexpr uint8_t kTxerr = 15;
constexpr uint8_t kFrame = 16; // frame information; ACR0 in reset mode
constexpr uint8_t kAmr0 = 20;
constexpr uint8_t kRmc = 29;
constexpr uint8_t kRbsa = 30;
constexpr uint8_t kCdr = 31;

// MOD (DS 6.4.3).
constexpr uint8_t kModRm = 0x01;
constexpr uint8_t kModLom = 0x02;
constexpr uint8_t kModStm = 0x04;
constexpr uint8_t kModAfm = 0x08;
// CMR (DS 6.4.4).
constexpr uint8_t kCmrTr = 0x01;
constexpr uint8_t kCmrAt = 0x02;
constexpr uint8_t kCmrRrb = 0x04;
constexpr uint8_t kCmrCdo = 0x08;
constexpr uint8_t kCmrSrr = 0x10;
// SR (DS 6.4.5).
constexpr uint8_t kSrRbs = 0x01;
constexpr uint8_t kSrTbs = 0x04;
constexpr uint8_t kSrTcs = 0x08;
constexpr uint8_t kSrRs = 0x10;
constexpr uint8_t kSrTs = 0x20;
constexpr uint8_t kSrEs = 0x40;
constexpr uint8_t kSrBs = 0x80;
// IR and IER (DS 6.4.6, 6.4.7).
constexpr uint8_t kIrRi = 0x01;
constexpr uint8_t kIrTi = 0x02;
constexpr uint8_t kIrEi = 0x04;
constexpr uint8_t kIrDoi = 0x08;
constexpr uint8_t kIrWui = 0x10;
constexpr uint8_t kIrEpi = 0x20;
constexpr uint8_t kIrAli = 0x40;
constexpr uint8_t kIrBei = 0x80;
// CDR (DS 6.5.4): PeliCAN, comparator bypass, CLKOUT off.
constexpr uint8_t kCdrPeliCan = 0x80;
constexpr uint8_t kCdrSetup = 0x80 | 0x40 | 0x08;
// OCR (DS 6.5.3): normal mode, TX0 push-pull.
constexpr uint8_t kOcrNormal = 0x1A;
// Frame information (DS 6.4.13).
constexpr uint8_t kFrameFf = 0x80;
constexpr uint8_t kFrameRtr = 0x40;
// ECC (DS 6.4.9): "other" error, transmitting, in the ACK slot.
constexpr uint8_t kEccAckError = 0xC0 | 0x19;

// Hardware reset values (DS 6.4.2, Table 8).
constexpr uint8_t kSrAfterReset = 0x3C;
constexpr uint8_t kEwlrAfterReset = 96;

// Bus timing for the 16 MHz crystal (tq = 125 ns * (BRP + 1)).
struct Timing {
    uint8_t btr0;
    uint8_t btr1;
    uint64_t bitNs;
};
constexpr Timing k125k{0x03, 0x1C, 8000};
constexpr Timing k500k{0x00, 0x1C, 2000};
constexpr Timing k1M{0x00, 0x14, 1000};

// Frame geometry with worst-case stuffing (docs/protocols/labbus.md):
// the CRC delimiter's bit index from SOF.
constexpr uint64_t crcDelimiter(bool extended, unsigned dlc, bool remote = false)
{
    const uint64_t stuffable = (extended ? 54u : 34u) + (remote ? 0u : 8u * (dlc > 8 ? 8 : dlc));
    return stuffable + (stuffable - 1) / 4;
}
// SOF to the end of EOF: where a frame completes.
constexpr uint64_t completionBits(bool extended, unsigned dlc) { return crcDelimiter(extended, dlc) + 10; }
// A lone transmitter's attempt: frame to the ACK slot, error flag,
// delimiter and intermission.
constexpr uint64_t ackErrorAttemptBits(bool extended, unsigned dlc) { return crcDelimiter(extended, dlc) + 19; }
// The ACK error is seen at the end of the ACK slot.
constexpr uint64_t ackErrorBits(bool extended, unsigned dlc) { return crcDelimiter(extended, dlc) + 2; }
constexpr uint64_t kSuspendBits = 8;
constexpr uint64_t kBusFreeBits = 11;
constexpr unsigned kRecoverySignals = 128;

// The uptime counts in steps of one 8254 period (838 ns); each poll of a
// register adds a few hundred instructions. Emulated times are checked to
// within this much.
constexpr uint64_t kResolutionNs = 2000;
constexpr uint64_t kMillisecond = 1000000;

uint16_t port(unsigned channel, uint8_t reg)
{
    return static_cast<uint16_t>(kCardBase + channel * kChannelPorts + reg);
}

uint8_t rd(unsigned channel, uint8_t reg) { return arch_x86::portRead8(port(channel, reg)); }

void wr(unsigned channel, uint8_t reg, uint8_t value) { arch_x86::portWrite8(port(channel, reg), value); }

bool near(uint64_t measured, uint64_t expected, uint64_t tolerance)
{
    return measured + tolerance >= expected && measured <= expected + tolerance;
}

/// Puts a channel in reset mode, PeliCAN, accepting every frame.
void configure(unsigned channel, const Timing& timing, uint8_t mode, uint8_t interruptEnable)
{
    wr(channel, kMod, kModRm);
    wr(channel, kCdr, kCdrSetup);
    wr(channel, kBtr0, timing.btr0);
    wr(channel, kBtr1, timing.btr1);
    wr(channel, kOcr, kOcrNormal);
    for (uint8_t i = 0; i < 4; ++i) {
        wr(channel, static_cast<uint8_t>(kFrame + i), 0x00);
        wr(channel, static_cast<uint8_t>(kAmr0 + i), 0xFF);
    }
    wr(channel, kIer, interruptEnable);
    wr(channel, kMod, static_cast<uint8_t>(kModRm | kModAfm | mode));
}

/// Leaves reset mode; the channel joins after a bus-free signal.
void start(unsigned channel, uint8_t mode) { wr(channel, kMod, static_cast<uint8_t>(kModAfm | mode)); }

/// Polls SR until (SR & mask) == value; false after timeoutNs.
bool waitStatus(unsigned channel, uint8_t mask, uint8_t value, uint64_t timeoutNs, uint64_t* when = nullptr)
{
    const uint64_t deadline = timerAgent.Uptime() + timeoutNs;
    for (;;) {
        const uint64_t now = timerAgent.Uptime();
        if ((rd(channel, kSr) & mask) == value) {
            if (when != nullptr) {
                *when = now;
            }
            return true;
        }
        if (now > deadline) {
            return false;
        }
    }
}

/// Loads a frame into the transmit buffer (DS 6.4.13).
void loadFrame(unsigned channel, uint32_t id, bool extended, bool remote, uint8_t dlc, const uint8_t* data)
{
    wr(channel, kFrame,
       static_cast<uint8_t>((extended ? kFrameFf : 0) | (remote ? kFrameRtr : 0) | (dlc & 0x0F)));
    uint8_t offset;
    if (extended) {
        wr(channel, kFrame + 1, static_cast<uint8_t>(id >> 21));
        wr(channel, kFrame + 2, static_cast<uint8_t>(id >> 13));
        wr(channel, kFrame + 3, static_cast<uint8_t>(id >> 5));
        wr(channel, kFrame + 4, static_cast<uint8_t>(id << 3));
        offset = 5;
    } else {
        wr(channel, kFrame + 1, static_cast<uint8_t>(id >> 3));
        wr(channel, kFrame + 2, static_cast<uint8_t>(id << 5));
        offset = 3;
    }
    const unsigned bytes = remote ? 0 : (dlc > 8 ? 8 : dlc);
    for (unsigned i = 0; i < bytes; ++i) {
        wr(channel, static_cast<uint8_t>(kFrame + offset + i), data[i]);
    }
}

/// A frame read from the receive buffer (DS 6.4.14).
struct RxFrame {
    uint8_t info;
    uint32_t id;
    uint8_t data[8];
};

RxFrame readFrame(unsigned channel)
{
    RxFrame frame{};
    frame.info = rd(channel, kFrame);
    uint8_t offset;
    if (frame.info & kFrameFf) {
        frame.id = (static_cast<uint32_t>(rd(channel, kFrame + 1)) << 21)
                   | (static_cast<uint32_t>(rd(channel, kFrame + 2)) << 13)
                   | (static_cast<uint32_t>(rd(channel, kFrame + 3)) << 5) | (rd(channel, kFrame + 4) >> 3);
        offset = 5;
    } else {
        frame.id = (static_cast<uint32_t>(rd(channel, kFrame + 1)) << 3) | (rd(channel, kFrame + 2) >> 5);
        offset = 3;
    }
    const unsigned dlc = frame.info & 0x0F;
    const unsigned bytes = (frame.info & kFrameRtr) ? 0 : (dlc > 8 ? 8 : dlc);
    for (unsigned i = 0; i < bytes; ++i) {
        frame.data[i] = rd(channel, static_cast<uint8_t>(kFrame + offset + i));
    }
    return frame;
}

// -- sjareg: reset values and access rules ---------------------------------------

bool resetValues(shell::Shell& shell, unsigned channel)
{
    // The chip comes out of a hardware reset in BasicCAN mode; the values
    // of Table 8 show in PeliCAN mode, entered in reset mode.
    wr(channel, kCdr, kCdrPeliCan);
    bool ok = check(shell, rd(channel, kCdr) == kCdrPeliCan, "CDR selects PeliCAN mode in reset mode");
    const uint8_t mod = rd(channel, kMod);
    const uint8_t sr = rd(channel, kSr);
    shell.print("channel %u: MOD %02x SR %02x IR %02x IER %02x EWLR %u RXERR %u TXERR %u RMC %u CMR %02x\r\n",
                channel, mod, sr, rd(channel, kIr), rd(channel, kIer), rd(channel, kEwlr), rd(channel, kRxerr),
                rd(channel, kTxerr), rd(channel, kRmc), rd(channel, kCmr));
    ok = check(shell, mod == kModRm, "MOD resets to reset mode") && ok;
    ok = check(shell, sr == kSrAfterReset, "SR resets to 3C (TBS TCS RS TS)") && ok;
    ok = check(shell, rd(channel, kIr) == 0 && rd(channel, kIer) == 0, "IR and IER reset to 0") && ok;
    ok = check(shell, rd(channel, kEwlr) == kEwlrAfterReset, "EWLR resets to 96") && ok;
    ok = check(shell, rd(channel, kRxerr) == 0 && rd(channel, kTxerr) == 0, "the error counters reset to 0") && ok;
    ok = check(shell, rd(channel, kRmc) == 0 && rd(channel, kRbsa) == 0, "RMC and RBSA reset to 0") && ok;
    ok = check(shell, rd(channel, kCmr) == 0xFF, "CMR reads FF") && ok;
    return ok;
}

bool registers(shell::Shell& shell)
{
    bool ok = true;
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        ok = resetValues(shell, channel) && ok;
    }

    // BTR0, BTR1, OCR, EWLR, ACR and AMR take any value in reset mode.
    configure(0, k500k, 0, 0);
    wr(0, kBtr0, 0xC7);
    wr(0, kBtr1, 0xFF);
    wr(0, kOcr, 0x5A);
    wr(0, kEwlr, 200);
    wr(0, kFrame, 0x12);
    wr(0, kAmr0, 0x34);
    ok = check(shell, rd(0, kBtr0) == 0xC7 && rd(0, kBtr1) == 0xFF, "BTR0 and BTR1 take any value") && ok;
    ok = check(shell, rd(0, kOcr) == 0x5A && rd(0, kEwlr) == 200, "OCR and EWLR read back") && ok;
    ok = check(shell, rd(0, kFrame) == 0x12 && rd(0, kAmr0) == 0x34, "ACR0 and AMR0 read back in reset mode") && ok;
    // The card's 8-bit data path: a 16-bit read is two byte reads.
    ok = check(shell, arch_x86::portRead16(port(0, kBtr0)) == 0xFFC7, "a 16-bit read returns BTR1:BTR0") && ok;
    wr(0, kRxerr, 50);
    wr(0, kTxerr, 60);
    ok = check(shell, rd(0, kRxerr) == 50 && rd(0, kTxerr) == 60, "RXERR and TXERR are written in reset mode") && ok;
    wr(0, kRxerr, 0);
    wr(0, kTxerr, 0);
    wr(0, kBtr0, k500k.btr0);
    wr(0, kBtr1, k500k.btr1);
    wr(0, kEwlr, kEwlrAfterReset);

    // In operating mode they are read only; so are the mode bits LOM, STM
    // and AFM, and the CAN mode bit of CDR (DS 6.4.3, 6.5).
    start(0, 0);
    wr(0, kBtr0, 0x3F);
    wr(0, kBtr1, 0x00);
    wr(0, kOcr, 0x00);
    wr(0, kEwlr, 10);
    wr(0, kRxerr, 77);
    wr(0, kTxerr, 88);
    wr(0, kMod, kModAfm | kModLom | kModStm);
    wr(0, kCdr, 0x00);
    ok = check(shell, rd(0, kBtr0) == k500k.btr0 && rd(0, kBtr1) == k500k.btr1, "BTR0 and BTR1 ignore writes in "
               "operating mode") && ok;
    ok = check(shell, rd(0, kOcr) == 0x5A && rd(0, kEwlr) == kEwlrAfterReset, "OCR and EWLR ignore writes in "
               "operating mode") && ok;
    ok = check(shell, rd(0, kRxerr) == 0 && rd(0, kTxerr) == 0, "the counters ignore writes in operating mode") && ok;
    ok = check(shell, rd(0, kMod) == kModAfm, "LOM and STM ignore writes in operating mode") && ok;
    ok = check(shell, (rd(0, kCdr) & kCdrPeliCan) != 0, "CDR keeps PeliCAN mode in operating mode") && ok;
    // Channel 1 is a chip of its own.
    ok = check(shell, rd(1, kMod) == kModRm && rd(1, kBtr0) == 0 && rd(1, kOcr) == 0, "channel 1 is untouched") && ok;

    // After a bus-free signal (11 bits, 22 us at 500 kbit/s) RS and TS clear.
    const uint64_t started = timerAgent.Uptime();
    uint64_t idle = 0;
    ok = check(shell, waitStatus(0, kSrRs | kSrTs, 0, kMillisecond, &idle), "RS and TS clear after bus-free") && ok;
    shell.print("channel 0 joined the bus %llu ns after reset mode ended\r\n",
                static_cast<unsigned long long>(idle - started));
    ok = check(shell, near(idle - started, kBusFreeBits * k500k.bitNs, kResolutionNs),
               "joining takes one bus-free signal") && ok;
    wr(0, kMod, kModRm);
    return ok;
}

DCOS_TARGET_TEST(sja1000RegistersTest, "sjareg",
                 "SJA1000 model: reset values, read-back, reset-mode-only registers, two chips", registers);

// -- sjalone: a node alone on its bus ----------------------------------------------

bool loneNode(shell::Shell& shell)
{
    // 125 kbit/s, every interrupt enabled but the line masked: IR is polled.
    configure(0, k125k, 0, 0xFF);
    start(0, 0);
    bool ok = check(shell, waitStatus(0, kSrRs | kSrTs, 0, kMillisecond), "channel 0 joins its lone bus");
    const uint8_t data[8] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
    loadFrame(0, 0x123, false, false, 8, data);
    (void)rd(0, kIr);

    // Every attempt ends in an ACK error: TXERR rises by 8 (ISO 11898-1
    // rule 3) once per attempt, an error-active attempt every 141 bits.
    constexpr unsigned kSteps = 16;
    uint64_t changes[kSteps] = {};
    uint8_t values[kSteps] = {};
    const uint64_t request = timerAgent.Uptime();
    wr(0, kCmr, kCmrTr);
    ok = check(shell, (rd(0, kSr) & (kSrTbs | kSrTcs)) == 0, "TR locks the buffer and clears TCS") && ok;
    uint8_t last = 0;
    for (unsigned step = 0; step < kSteps; ++step) {
        const uint64_t deadline = timerAgent.Uptime() + 10 * kMillisecond;
        uint8_t value;
        while ((value = rd(0, kTxerr)) == last && timerAgent.Uptime() < deadline) {
        }
        changes[step] = timerAgent.Uptime();
        values[step] = value;
        last = value;
    }
    const uint64_t attemptNs = ackErrorAttemptBits(false, 8) * k125k.bitNs;
    unsigned wrong = 0;
    for (unsigned step = 0; step < kSteps; ++step) {
        const uint64_t expected = request + ackErrorBits(false, 8) * k125k.bitNs + step * attemptNs;
        if (values[step] != 8 * (step + 1) || !near(changes[step], expected, kResolutionNs)) {
            shell.print("attempt %u: TXERR %u at +%llu ns, expected %u at +%llu ns\r\n", step + 1, values[step],
                        static_cast<unsigned long long>(changes[step] - request), 8 * (step + 1),
                        static_cast<unsigned long long>(expected - request));
            ++wrong;
        }
    }
    shell.print("16 attempts, TXERR 8 to %u, one every %llu ns\r\n", values[kSteps - 1],
                static_cast<unsigned long long>((changes[kSteps - 1] - changes[0]) / (kSteps - 1)));
    ok = check(shell, wrong == 0, "TXERR +8 per attempt at the ACK slot, 141 bit times apart") && ok;

    // ES came at 96, error passive at 128: EI, EPI and BEI are pending.
    const uint8_t ir = rd(0, kIr);
    const uint8_t sr = rd(0, kSr);
    shell.print("IR %02x SR %02x ECC %02x\r\n", ir, sr, rd(0, kEcc));
    ok = check(shell, (ir & (kIrEi | kIrEpi | kIrBei)) == (kIrEi | kIrEpi | kIrBei), "EI, EPI and BEI raised") && ok;
    ok = check(shell, (ir & kIrTi) == 0, "no TI: the frame is still pending") && ok;
    ok = check(shell, (sr & (kSrEs | kSrBs | kSrTbs)) == kSrEs, "SR: ES, not bus-off, buffer locked") && ok;

    // Error passive, the ACK error no longer counts (the exception of
    // rule 3): TXERR stays at 128 while the attempts go on, 8 bits of
    // suspend transmission apart. ECC captures again once read.
    spin(20 * kMillisecond);
    const uint8_t ecc = rd(0, kEcc);
    ok = check(shell, rd(0, kTxerr) == 128, "TXERR stays at 128 in error passive") && ok;
    ok = check(shell, ecc == kEccAckError, "ECC: other error, transmitting, ACK slot") && ok;
    ok = check(shell, (rd(0, kIr) & kIrBei) != 0 && (rd(0, kSr) & kSrTbs) == 0, "the attempts go on") && ok;
    (void)rd(0, kEcc);
    // Each read of IR clears it, so the loop sees every BEI once.
    uint64_t errors[2] = {};
    for (uint64_t& when : errors) {
        const uint64_t deadline = timerAgent.Uptime() + 10 * kMillisecond;
        while ((rd(0, kIr) & kIrBei) == 0 && timerAgent.Uptime() < deadline) {
        }
        when = timerAgent.Uptime();
    }
    const uint64_t first = errors[0];
    const uint64_t second = errors[1];
    const uint64_t passiveAttemptNs = (ackErrorAttemptBits(false, 8) + kSuspendBits) * k125k.bitNs;
    shell.print("error passive: an attempt every %llu ns\r\n", static_cast<unsigned long long>(second - first));
    ok = check(shell, near(second - first, passiveAttemptNs, kResolutionNs), "passive attempts are 149 bits apart")
         && ok;

    // AT: the attempt under way finishes and is not repeated (DS 6.4.4).
    wr(0, kCmr, kCmrAt);
    ok = check(shell, waitStatus(0, kSrTbs, kSrTbs, 2 * passiveAttemptNs), "AT releases the buffer") && ok;
    ok = check(shell, (rd(0, kSr) & kSrTcs) == 0 && (rd(0, kIr) & kIrTi) != 0, "aborted: TCS clear, TI") && ok;
    spin(2 * passiveAttemptNs);
    ok = check(shell, (rd(0, kIr) & kIrBei) == 0, "no attempt after the abort") && ok;

    // Single shot (TR with AT): one attempt, TXERR unchanged in error
    // passive, the buffer released with TCS clear.
    wr(0, kCmr, kCmrTr | kCmrAt);
    ok = check(shell, waitStatus(0, kSrTbs, kSrTbs, 2 * passiveAttemptNs), "a single shot ends after one attempt")
         && ok;
    ok = check(shell, (rd(0, kSr) & kSrTcs) == 0 && (rd(0, kIr) & (kIrTi | kIrBei)) == (kIrTi | kIrBei),
               "single shot: TCS clear, TI and BEI") && ok;
    spin(2 * passiveAttemptNs);
    ok = check(shell, (rd(0, kIr) & kIrBei) == 0, "no retransmission after a single shot") && ok;
    wr(0, kMod, kModRm);
    return ok;
}

DCOS_TARGET_TEST(sja1000LoneNodeTest, "sjalone",
                 "SJA1000 model: a lone node's ACK errors, TEC +8 to error passive and no further, AT, single shot",
                 loneNode);

// -- sjaselftest: self test mode and self reception ----------------------------------

bool selfTest(shell::Shell& shell)
{
    // At 1 Mbit/s with STM: a transmission succeeds without acknowledge,
    // and SRR receives it; it completes at the end of EOF.
    configure(1, k1M, kModStm, 0xFF);
    start(1, kModStm);
    bool ok = check(shell, waitStatus(1, kSrRs | kSrTs, 0, kMillisecond), "channel 1 joins its lone bus");
    struct Case {
        uint32_t id;
        bool extended;
        uint8_t dlc;
    };
    static constexpr Case cases[] = {{0x555, false, 4}, {0x7FF, false, 0}, {0x1ABCDEF0, true, 8}, {0x001, false, 8}};
    const uint8_t data[8] = {0xDE, 0xAD, 0xBE, 0xEF, 0x01, 0x02, 0x03, 0x04};
    for (const Case& c : cases) {
        (void)rd(1, kIr);
        loadFrame(1, c.id, c.extended, false, c.dlc, data);
        const uint64_t request = timerAgent.Uptime();
        wr(1, kCmr, kCmrSrr);
        uint64_t received = 0;
        const bool arrived = waitStatus(1, kSrRbs, kSrRbs, kMillisecond, &received);
        const uint8_t sr = rd(1, kSr);
        const uint8_t ir = rd(1, kIr);
        const RxFrame frame = readFrame(1);
        wr(1, kCmr, kCmrRrb);
        const uint64_t expected = completionBits(c.extended, c.dlc) * k1M.bitNs;
        shell.print("%s %x DLC %u: received after %llu ns (%llu bits expected), SR %02x IR %02x\r\n",
                    c.extended ? "extended" : "standard", static_cast<unsigned>(c.id), c.dlc,
                    static_cast<unsigned long long>(received - request),
                    static_cast<unsigned long long>(completionBits(c.extended, c.dlc)), sr, ir);
        ok = check(shell, arrived && near(received - request, expected, kResolutionNs),
                   "self reception at the end of EOF") && ok;
        ok = check(shell, (sr & (kSrTbs | kSrTcs)) == (kSrTbs | kSrTcs), "TBS and TCS set") && ok;
        ok = check(shell, (ir & (kIrTi | kIrRi)) == (kIrTi | kIrRi), "TI and RI raised") && ok;
        bool same = frame.id == c.id && (frame.info & 0x0F) == c.dlc && ((frame.info & kFrameFf) != 0) == c.extended;
        for (unsigned i = 0; i < c.dlc; ++i) {
            same = same && frame.data[i] == data[i];
        }
        ok = check(shell, same, "the received frame is the one sent") && ok;
    }
    ok = check(shell, rd(1, kTxerr) == 0 && rd(1, kRmc) == 0, "no errors, the FIFO released") && ok;

    // TR without SRR in self test mode: sent, not received.
    loadFrame(1, 0x100, false, false, 1, data);
    wr(1, kCmr, kCmrTr);
    ok = check(shell, waitStatus(1, kSrTcs, kSrTcs, kMillisecond), "TR in self test mode completes") && ok;
    ok = check(shell, rd(1, kRmc) == 0, "TR does not receive its own frame") && ok;

    // The buffer is locked while a transmission is pending: bytes written
    // then are lost (DS 6.4.5), and the frame sent is the one requested.
    configure(1, k125k, kModStm, 0xFF);
    start(1, kModStm);
    ok = check(shell, waitStatus(1, kSrRs | kSrTs, 0, kMillisecond), "channel 1 joins again") && ok;
    loadFrame(1, 0x321, false, false, 2, data);
    wr(1, kCmr, kCmrSrr);
    const uint8_t other[8] = {0x99, 0x99};
    loadFrame(1, 0x7AA, false, false, 2, other);
    ok = check(shell, waitStatus(1, kSrRbs, kSrRbs, 10 * kMillisecond), "the locked frame arrives") && ok;
    const RxFrame locked = readFrame(1);
    wr(1, kCmr, kCmrRrb);
    ok = check(shell, locked.id == 0x321 && locked.data[0] == 0xDE && locked.data[1] == 0xAD,
               "writes to a locked transmit buffer are lost") && ok;
    wr(1, kMod, kModRm);
    return ok;
}

DCOS_TARGET_TEST(sja1000SelfTestTest, "sjaselftest",
                 "SJA1000 model: self test and self reception at 1 Mbit/s, exact frame lengths, the buffer lock",
                 selfTest);

// -- sjabusoff: bus-off and its recovery ---------------------------------------------

bool busOff(shell::Shell& shell)
{
    configure(0, k500k, 0, 0xFF);
    (void)rd(0, kIr);
    // Writing 255 to TXERR in reset mode is a CPU-driven bus-off (DS 6.4.12).
    wr(0, kTxerr, 255);
    uint8_t sr = rd(0, kSr);
    uint8_t ir = rd(0, kIr);
    shell.print("after TXERR=255: SR %02x IR %02x TXERR %u RXERR %u MOD %02x\r\n", sr, ir, rd(0, kTxerr),
                rd(0, kRxerr), rd(0, kMod));
    bool ok = check(shell, (sr & (kSrBs | kSrEs)) == (kSrBs | kSrEs), "BS and ES set");
    ok = check(shell, (ir & kIrEi) != 0, "EI raised") && ok;
    ok = check(shell, rd(0, kTxerr) == 127 && rd(0, kRxerr) == 0, "TXERR 127, RXERR 0") && ok;
    wr(0, kRxerr, 9);
    ok = check(shell, rd(0, kRxerr) == 0, "RXERR cannot be written while bus-off") && ok;

    // Leaving reset mode starts the recovery: 128 bus-free signals of 11
    // bits each, counted down in TXERR.
    const uint64_t released = timerAgent.Uptime();
    start(0, 0);
    ok = check(shell, (rd(0, kMod) & kModRm) == 0, "reset mode ends at once") && ok;
    spin(20 * kBusFreeBits * k500k.bitNs + kBusFreeBits * k500k.bitNs / 2);
    const uint8_t counting = rd(0, kTxerr);
    shell.print("TXERR %u after 20.5 bus-free times\r\n", counting);
    ok = check(shell, counting == 127 - 20, "TXERR counts the bus-free signals down") && ok;
    ok = check(shell, (rd(0, kSr) & kSrBs) != 0, "still bus-off") && ok;
    uint64_t recovered = 0;
    ok = check(shell, waitStatus(0, kSrBs, 0, 10 * kMillisecond, &recovered), "bus-off ends") && ok;
    const uint64_t expected = kRecoverySignals * kBusFreeBits * k500k.bitNs;
    sr = rd(0, kSr);
    shell.print("recovered after %llu ns (%llu expected): SR %02x TXERR %u\r\n",
                static_cast<unsigned long long>(recovered - released), static_cast<unsigned long long>(expected), sr,
                rd(0, kTxerr));
    ok = check(shell, near(recovered - released, expected, kResolutionNs), "128 x 11 bit times") && ok;
    ok = check(shell, (sr & (kSrBs | kSrEs)) == 0 && rd(0, kTxerr) == 0, "bus-on, ES clear, counters reset") && ok;
    ok = check(shell, (rd(0, kIr) & kIrEi) != 0, "EI raised again") && ok;

    // TXERR 0..254 written in bus-off clears BS: one bus-free signal then.
    wr(0, kMod, kModRm);
    wr(0, kTxerr, 255);
    wr(0, kTxerr, 40);
    ok = check(shell, (rd(0, kSr) & kSrBs) == 0 && rd(0, kTxerr) == 40, "TXERR 40 clears bus-off") && ok;
    const uint64_t restarted = timerAgent.Uptime();
    start(0, 0);
    uint64_t joined = 0;
    ok = check(shell, waitStatus(0, kSrRs | kSrTs, 0, kMillisecond, &joined), "the channel joins") && ok;
    ok = check(shell, near(joined - restarted, kBusFreeBits * k500k.bitNs, kResolutionNs),
               "after one bus-free signal") && ok;
    wr(0, kMod, kModRm);
    return ok;
}

DCOS_TARGET_TEST(sja1000BusOffTest, "sjabusoff",
                 "SJA1000 model: CPU-driven bus-off, recovery after 128 bus-free signals counted in TXERR", busOff);

// -- sjalisten: listen-only mode ---------------------------------------------------

bool listenOnly(shell::Shell& shell)
{
    configure(0, k1M, kModLom, 0xFF);
    start(0, kModLom);
    bool ok = check(shell, rd(0, kMod) == (kModAfm | kModLom), "LOM set in reset mode stays");
    ok = check(shell, waitStatus(0, kSrRs | kSrTs, 0, kMillisecond), "the channel joins") && ok;
    const uint8_t data[1] = {0x42};
    loadFrame(0, 0x10, false, false, 1, data);
    wr(0, kCmr, kCmrTr);
    spin(kMillisecond);
    ok = check(shell, (rd(0, kSr) & (kSrTbs | kSrTs)) == kSrTbs, "TR is ignored: nothing is sent") && ok;
    ok = check(shell, (rd(0, kIr) & (kIrBei | kIrTi)) == 0 && rd(0, kTxerr) == 0, "no attempt, no error") && ok;
    wr(0, kMod, kModRm);
    return ok;
}

DCOS_TARGET_TEST(sja1000ListenOnlyTest, "sjalisten", "SJA1000 model: listen-only mode never transmits",
                 listenOnly);

// -- the interrupt routine shared by sjairq and canlab --------------------------------

// What the routine saw, in order. Entries are written by the routine and
// read by the console command; the count is the commit point.
enum class Kind : uint8_t { Receive, Transmit, ErrorWarning, Overrun, WakeUp, ErrorPassive, ArbitrationLost, BusError };

struct Entry {
    uint64_t uptime;
    Kind kind;
    uint8_t status;
    uint8_t a; // TXERR, ALC or ECC
    uint8_t b; // RXERR
    RxFrame frame;
};

constexpr unsigned kLogSize = 256;

struct ChannelLog {
    Entry entries[kLogSize];
    volatile unsigned written;
    volatile unsigned dropped;
    volatile unsigned interrupts;
    volatile bool echo;
    volatile bool installed;
};

ChannelLog logs[kChannels];

void record(unsigned channel, const Entry& entry)
{
    ChannelLog& log = logs[channel];
    if (log.written >= kLogSize) {
        log.dropped = log.dropped + 1;
        return;
    }
    log.entries[log.written] = entry;
    log.written = log.written + 1;
}

/// Echo mode: answers a received data frame with identifier + 1, at once.
void echo(unsigned channel, const RxFrame& frame)
{
    if (!(rd(channel, kSr) & kSrTbs) || (frame.info & kFrameRtr)) {
        return;
    }
    const bool extended = (frame.info & kFrameFf) != 0;
    const uint32_t id = (frame.id + 1) & (extended ? 0x1FFFFFFFu : 0x7FFu);
    loadFrame(channel, id, extended, false, frame.info & 0x0F, frame.data);
    wr(channel, kCmr, kCmrTr);
}

void channelIsr(void* context)
{
    const unsigned channel = static_cast<unsigned>(reinterpret_cast<uintptr_t>(context));
    const uint64_t now = timerAgent.Uptime();
    logs[channel].interrupts = logs[channel].interrupts + 1;
    for (;;) {
        const uint8_t ir = rd(channel, kIr);
        if (ir == 0) {
            return;
        }
        Entry entry{};
        entry.uptime = now;
        entry.status = rd(channel, kSr);
        if (ir & kIrRi) {
            while (rd(channel, kSr) & kSrRbs) {
                entry.kind = Kind::Receive;
                entry.frame = readFrame(channel);
                wr(channel, kCmr, kCmrRrb);
                record(channel, entry);
                if (logs[channel].echo) {
                    echo(channel, entry.frame);
                }
            }
        }
        if (ir & kIrTi) {
            entry.kind = Kind::Transmit;
            record(channel, entry);
        }
        if (ir & kIrEi) {
            entry.kind = Kind::ErrorWarning;
            entry.a = rd(channel, kTxerr);
            entry.b = rd(channel, kRxerr);
            record(channel, entry);
        }
        if (ir & kIrDoi) {
            wr(channel, kCmr, kCmrCdo);
            entry.kind = Kind::Overrun;
            record(channel, entry);
        }
        if (ir & kIrWui) {
            entry.kind = Kind::WakeUp;
            record(channel, entry);
        }
        if (ir & kIrEpi) {
            entry.kind = Kind::ErrorPassive;
            entry.a = rd(channel, kTxerr);
            entry.b = rd(channel, kRxerr);
            record(channel, entry);
        }
        if (ir & kIrAli) {
            entry.kind = Kind::ArbitrationLost;
            entry.a = rd(channel, kAlc);
            record(channel, entry);
        }
        if (ir & kIrBei) {
            entry.kind = Kind::BusError;
            entry.a = rd(channel, kEcc);
            entry.b = rd(channel, kRxerr);
            entry.status = rd(channel, kTxerr); // the TX count, for BEI
            record(channel, entry);
        }
    }
}

bool installIsr(shell::Shell& shell, unsigned channel)
{
    if (logs[channel].installed) {
        return true;
    }
    const Status status = systemAgent.InstallISR(kLines[channel], channelIsr,
                                                 reinterpret_cast<void*>(static_cast<uintptr_t>(channel)));
    if (status != Status::Ok) {
        shell.print("error: InstallISR on IRQ %u: %s (is a CAN driver using the card?)\r\n", kLines[channel],
                    dcos::statusName(status));
        return false;
    }
    logs[channel].installed = true;
    return true;
}

void removeIsr(unsigned channel)
{
    if (logs[channel].installed) {
        (void)systemAgent.RemoveISR(kLines[channel]);
        logs[channel].installed = false;
    }
}

void clearLog(unsigned channel)
{
    arch_x86::InterruptGuard guard;
    logs[channel].written = 0;
    logs[channel].dropped = 0;
    logs[channel].interrupts = 0;
}

unsigned countKind(unsigned channel, Kind kind)
{
    unsigned count = 0;
    for (unsigned i = 0; i < logs[channel].written; ++i) {
        count += logs[channel].entries[i].kind == kind ? 1 : 0;
    }
    return count;
}

// -- sjairq: both interrupt lines ------------------------------------------------------

bool interrupts(shell::Shell& shell)
{
    bool ok = true;
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        configure(channel, k500k, kModStm, kIrRi | kIrTi);
        clearLog(channel);
        if (!installIsr(shell, channel)) {
            return false;
        }
        start(channel, kModStm);
    }
    const uint8_t data[2] = {0xA5, 0x5A};
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        ok = check(shell, waitStatus(channel, kSrRs | kSrTs, 0, kMillisecond), "the channel joins") && ok;
        loadFrame(channel, 0x200 + channel, false, false, 2, data);
        wr(channel, kCmr, kCmrSrr);
    }
    (void)taskAgent.SleepFor(5 * kMillisecond);
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        const unsigned received = countKind(channel, Kind::Receive);
        const unsigned sent = countKind(channel, Kind::Transmit);
        shell.print("channel %u (IRQ %u): %u interrupts, %u RI, %u TI\r\n", channel, kLines[channel],
                    logs[channel].interrupts, received, sent);
        ok = check(shell, received == 1 && sent == 1, "one RI and one TI on the channel's own line") && ok;
        ok = check(shell, received == 1 && logs[channel].entries[0].frame.id == 0x200 + channel,
                   "the frame of this channel") && ok;
        ok = check(shell, rd(channel, kIr) == 0, "the routine left IR clear") && ok;
        wr(channel, kMod, kModRm);
        wr(channel, kIer, 0);
        removeIsr(channel);
    }
    return ok;
}

DCOS_TARGET_TEST(sja1000InterruptTest, "sjairq", "SJA1000 model: channel 0 interrupts on IRQ 10, channel 1 on IRQ 11",
                 interrupts);

// -- canlab: the console helper of the multi-board tests ----------------------------------

bool parseChannel(const char* text, unsigned& channel)
{
    unsigned long value;
    if (!shell::Shell::parseUnsigned(text, value) || value >= kChannels) {
        return false;
    }
    channel = static_cast<unsigned>(value);
    return true;
}

bool parseHex(const char* text, uint32_t& value)
{
    value = 0;
    if (*text == '\0') {
        return false;
    }
    for (; *text != '\0'; ++text) {
        unsigned digit;
        if (*text >= '0' && *text <= '9') {
            digit = static_cast<unsigned>(*text - '0');
        } else if (*text >= 'a' && *text <= 'f') {
            digit = static_cast<unsigned>(*text - 'a' + 10);
        } else if (*text >= 'A' && *text <= 'F') {
            digit = static_cast<unsigned>(*text - 'A' + 10);
        } else {
            return false;
        }
        if (value > 0x0FFFFFFFu) {
            return false;
        }
        value = (value << 4) | digit;
    }
    return true;
}

bool parseData(const char* text, uint8_t* data, uint8_t& length)
{
    length = 0;
    if (runtime::textEquals(text, "-")) {
        return true;
    }
    char pair[3] = {};
    while (text[0] != '\0') {
        if (text[1] == '\0' || length == 8) {
            return false;
        }
        pair[0] = text[0];
        pair[1] = text[1];
        uint32_t byte;
        if (!parseHex(pair, byte)) {
            return false;
        }
        data[length++] = static_cast<uint8_t>(byte);
        text += 2;
    }
    return true;
}

bool startsWith(const char* text, const char* prefix)
{
    while (*prefix != '\0') {
        if (*text++ != *prefix++) {
            return false;
        }
    }
    return true;
}

const char* kindName(Kind kind)
{
    switch (kind) {
    case Kind::Receive:
        return "RX";
    case Kind::Transmit:
        return "TI";
    case Kind::ErrorWarning:
        return "EI";
    case Kind::Overrun:
        return "DOI";
    case Kind::WakeUp:
        return "WUI";
    case Kind::ErrorPassive:
        return "EPI";
    case Kind::ArbitrationLost:
        return "ALI";
    case Kind::BusError:
        return "BEI";
    }
    return "?";
}

void printEntry(shell::Shell& shell, unsigned channel, const Entry& entry)
{
    shell.print("CANLOG %u %llu %s", channel, static_cast<unsigned long long>(entry.uptime), kindName(entry.kind));
    switch (entry.kind) {
    case Kind::Receive: {
        const RxFrame& frame = entry.frame;
        const unsigned dlc = frame.info & 0x0F;
        const unsigned bytes = (frame.info & kFrameRtr) ? 0 : (dlc > 8 ? 8 : dlc);
        shell.print(" %x %c%c %u ", static_cast<unsigned>(frame.id), (frame.info & kFrameFf) ? 'X' : 'S',
                    (frame.info & kFrameRtr) ? 'R' : 'D', dlc);
        if (bytes == 0) {
            shell.print("-");
        }
        for (unsigned i = 0; i < bytes; ++i) {
            shell.print("%02x", frame.data[i]);
        }
        break;
    }
    case Kind::Transmit:
        shell.print(" sr=%02x", entry.status);
        break;
    case Kind::ErrorWarning:
    case Kind::ErrorPassive:
        shell.print(" sr=%02x tx=%u rx=%u", entry.status, entry.a, entry.b);
        break;
    case Kind::ArbitrationLost:
        shell.print(" alc=%u", entry.a);
        break;
    case Kind::BusError:
        shell.print(" ecc=%02x tx=%u rx=%u", entry.a, entry.status, entry.b);
        break;
    default:
        shell.print(" sr=%02x", entry.status);
        break;
    }
    shell.print("\r\n");
}

shell::CommandResult canlabInit(shell::Shell& shell, unsigned channel, int argc, char** argv)
{
    unsigned long btr0;
    unsigned long btr1;
    if (argc < 5 || !shell::Shell::parseUnsigned(argv[3], btr0) || !shell::Shell::parseUnsigned(argv[4], btr1)
        || btr0 > 0xFF || btr1 > 0xFF) {
        return shell::CommandResult::UsageError;
    }
    uint8_t mode = 0;
    for (int i = 5; i < argc; ++i) {
        if (runtime::textEquals(argv[i], "listen")) {
            mode |= kModLom;
        } else if (runtime::textEquals(argv[i], "selftest")) {
            mode |= kModStm;
        } else {
            return shell::CommandResult::UsageError;
        }
    }
    logs[channel].echo = false;
    const Timing timing{static_cast<uint8_t>(btr0), static_cast<uint8_t>(btr1), 0};
    configure(channel, timing, mode, 0xFF);
    clearLog(channel);
    if (!installIsr(shell, channel)) {
        return shell::CommandResult::Failed;
    }
    start(channel, mode);
    shell.print("CANINIT %u btr0=%02x btr1=%02x mod=%02x\r\n", channel, static_cast<unsigned>(btr0),
                static_cast<unsigned>(btr1), rd(channel, kMod));
    return shell::CommandResult::Ok;
}

/// canlab send <ch> <id> <data> [ext] [rtr] [dlc=N] [once] [self] [at=NS] [count=N]
shell::CommandResult canlabSend(shell::Shell& shell, unsigned channel, int argc, char** argv)
{
    uint32_t id;
    uint8_t data[8];
    uint8_t length;
    if (argc < 5 || !parseHex(argv[3], id) || !parseData(argv[4], data, length)) {
        return shell::CommandResult::UsageError;
    }
    bool extended = false;
    bool remote = false;
    uint8_t command = kCmrTr;
    unsigned long dlc = length;
    unsigned long at = 0;
    unsigned long long atNs = 0;
    unsigned long count = 1;
    for (int i = 5; i < argc; ++i) {
        if (runtime::textEquals(argv[i], "ext")) {
            extended = true;
        } else if (runtime::textEquals(argv[i], "rtr")) {
            remote = true;
        } else if (runtime::textEquals(argv[i], "once")) {
            command |= kCmrAt;
        } else if (runtime::textEquals(argv[i], "self")) {
            command = static_cast<uint8_t>((command & ~kCmrTr) | kCmrSrr);
        } else if (startsWith(argv[i], "dlc=") && shell::Shell::parseUnsigned(argv[i] + 4, dlc) && dlc <= 15) {
        } else if (startsWith(argv[i], "at=") && shell::Shell::parseUnsigned(argv[i] + 3, at)) {
            // at= counts milliseconds of uptime (32-bit), for boards to start together.
            atNs = static_cast<unsigned long long>(at) * kMillisecond;
        } else if (startsWith(argv[i], "count=") && shell::Shell::parseUnsigned(argv[i] + 6, count) && count >= 1
                   && count <= 64) {
        } else {
            return shell::CommandResult::UsageError;
        }
    }
    const bool lengthFits = remote ? length == 0 : (dlc <= 8 ? dlc == length : length == 8);
    if (id > (extended ? 0x1FFFFFFFu : 0x7FFu) || !lengthFits) {
        shell.print("error: identifier %x, DLC %lu and %u data bytes do not make a frame\r\n",
                    static_cast<unsigned>(id), dlc, length);
        return shell::CommandResult::Failed;
    }
    if (!(rd(channel, kSr) & kSrTbs)) {
        shell.print("error: channel %u has a transmission pending\r\n", channel);
        return shell::CommandResult::Failed;
    }
    uint64_t requests[64];
    bool completed = true;
    loadFrame(channel, id, extended, remote, static_cast<uint8_t>(dlc), data);
    if (atNs != 0) {
        const uint64_t now = timerAgent.Uptime();
        if (now >= atNs) {
            shell.print("error: uptime %llu ns is past at=%lu ms\r\n", static_cast<unsigned long long>(now), at);
            return shell::CommandResult::Failed;
        }
        // The wake-up comes with the first tick at or after atNs, the same
        // on every board that booted alike: they request together.
        (void)taskAgent.SleepFor(atNs - now);
    }
    for (unsigned long n = 0; n < count; ++n) {
        if (n > 0) {
            if (!waitStatus(channel, kSrTbs, kSrTbs, 1000 * kMillisecond)) {
                completed = false;
                count = n;
                break;
            }
            loadFrame(channel, id, extended, remote, static_cast<uint8_t>(dlc), data);
        }
        // The uptime and the request it dates are one step: an interrupt
        // between them (the tick's takes over a microsecond) would date the
        // request early by its length.
        arch_x86::InterruptGuard guard;
        requests[n] = timerAgent.Uptime();
        wr(channel, kCmr, command);
    }
    for (unsigned long n = 0; n < count; ++n) {
        shell.print("CANTX %u %llu %x\r\n", channel, static_cast<unsigned long long>(requests[n]),
                    static_cast<unsigned>(id));
    }
    if (!completed) {
        shell.print("error: the transmit buffer stayed locked for 1 s\r\n");
        return shell::CommandResult::Failed;
    }
    return shell::CommandResult::Ok;
}

shell::CommandResult canlab(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    if (argc < 3 || !parseChannel(argv[2], channel)) {
        return shell::CommandResult::UsageError;
    }
    const char* verb = argv[1];
    if (runtime::textEquals(verb, "init")) {
        return canlabInit(shell, channel, argc, argv);
    }
    if (runtime::textEquals(verb, "send")) {
        return canlabSend(shell, channel, argc, argv);
    }
    if (runtime::textEquals(verb, "log") && argc == 3) {
        unsigned printed = 0;
        for (;;) {
            Entry entry;
            {
                arch_x86::InterruptGuard guard;
                if (printed >= logs[channel].written) {
                    break;
                }
                entry = logs[channel].entries[printed];
            }
            printEntry(shell, channel, entry);
            ++printed;
        }
        shell.print("CANLOG %u end %u dropped=%u\r\n", channel, printed, logs[channel].dropped);
        // Entries the routine added while printing stay for the next log.
        arch_x86::InterruptGuard guard;
        ChannelLog& log = logs[channel];
        for (unsigned i = printed; i < log.written; ++i) {
            log.entries[i - printed] = log.entries[i];
        }
        log.written = log.written - printed;
        log.dropped = 0;
        return shell::CommandResult::Ok;
    }
    if (runtime::textEquals(verb, "regs") && argc == 3) {
        // Only registers whose read has no side effect (not IR, ALC, ECC).
        shell.print("CANREGS %u mod=%02x sr=%02x ier=%02x txerr=%u rxerr=%u ewlr=%u rmc=%u uptime=%llu\r\n", channel,
                    rd(channel, kMod), rd(channel, kSr), rd(channel, kIer), rd(channel, kTxerr), rd(channel, kRxerr),
                    rd(channel, kEwlr), rd(channel, kRmc), static_cast<unsigned long long>(timerAgent.Uptime()));
        return shell::CommandResult::Ok;
    }
    if (runtime::textEquals(verb, "echo") && argc == 4) {
        logs[channel].echo = runtime::textEquals(argv[3], "on");
        return shell::CommandResult::Ok;
    }
    if ((runtime::textEquals(verb, "reset") || runtime::textEquals(verb, "start")) && argc == 3) {
        // The uptime of the write, for tests that time what follows it.
        const uint8_t mod = rd(channel, kMod);
        const uint8_t next = runtime::textEquals(verb, "reset") ? static_cast<uint8_t>(mod | kModRm)
                                                                : static_cast<uint8_t>(mod & ~kModRm);
        uint64_t now;
        {
            arch_x86::InterruptGuard guard;  // the uptime dates this write, not an interrupt before it
            now = timerAgent.Uptime();
            wr(channel, kMod, next);
        }
        shell.print("CANMODE %u %llu mod=%02x\r\n", channel, static_cast<unsigned long long>(now), rd(channel, kMod));
        return shell::CommandResult::Ok;
    }
    if (runtime::textEquals(verb, "abort") && argc == 3) {
        wr(channel, kCmr, kCmrAt);
        return shell::CommandResult::Ok;
    }
    if (runtime::textEquals(verb, "off") && argc == 3) {
        wr(channel, kMod, kModRm);
        wr(channel, kIer, 0);
        removeIsr(channel);
        return shell::CommandResult::Ok;
    }
    return shell::CommandResult::UsageError;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(
    canlabCommand, "canlab", "drive the SJA1000 card for the lab's CAN tests (test image only)",
    "canlab init <ch> <btr0> <btr1> [listen] [selftest] | send <ch> <id> <data|-> [ext] [rtr] [dlc=N] [once] [self] "
    "[at=MS] [count=N] | log <ch> | regs <ch> | echo <ch> on|off | reset|start|abort|off <ch>",
    "  init: reset mode, PeliCAN, accept all, every interrupt, the routine on IRQ 10/11, operating mode\r\n"
    "  send: id and data in hex; at= waits for that uptime in ms; count= sends back to back; prints CANTX\r\n"
    "  log: what the interrupt routine saw since the last log, as CANLOG <ch> <uptime ns> <event> ...\r\n"
    "  echo on: answer every data frame received with identifier + 1 from the interrupt routine",
    canlab);

} // namespace target_test
