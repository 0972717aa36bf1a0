// The emulator's RS-485 UART model (isa-rs485-uart, tests_renode/models/
// isa_rs485.c) register by register, from the controller: raw port I/O on
// COM2, no driver. The harness boots the test image with COM2 replaced by
// the model and on no line (test_modbus_line.py), so every character here
// goes through the model's loopback (MCR.LOOP, PC16550D section 8.8), and
// its timing is the model's own: a character lasts start + data + parity +
// stop bits at the divisor's bit time.
//
// The interrupt output stays off the ISA bus (MCR.OUT2 clear), so the
// interrupt sources are read in IIR without an interrupt handler.
#include "KernelTestSupport.hpp"

#include <dcos/TimerAgent.hpp>

#include <arch_x86/PortIo.hpp>
#include <bsp/Board.hpp>
#include <bsp/Uart16550.hpp>

namespace target_test {

namespace {

using bsp::Uart16550;
using dcos::timerAgent;

// MSR bits (PC16550D section 8.9, "Modem Status Register"); the driver
// reads MSR only to clear it, so it names none of them.
constexpr uint8_t kMsrDeltaCts = 1u << 0;
constexpr uint8_t kMsrDeltaDsr = 1u << 1;
constexpr uint8_t kMsrCts = 1u << 4;
constexpr uint8_t kMsrDsr = 1u << 5;
// IIR bits 7-6 read 11 while the FIFOs are on (section 8.6, Table IV).
constexpr uint8_t kIirFifosOn = 0xC0;
// LSR bit 7: an error in the receiver FIFO (section 8.4).
constexpr uint8_t kLsrFifoError = 1u << 7;
// 19200 baud from the 1.8432 MHz clock (section 8.10, Table III).
constexpr uint16_t kDivisor19200 = 6;
// LCR for 8E1 and 7N2: word length, stop bits, parity (section 8.1).
constexpr uint8_t kLcr8E1 = Uart16550::lcrWordLength8 | Uart16550::lcrParityEnable | Uart16550::lcrEvenParity;
constexpr uint8_t kLcr7N2 = 2u | Uart16550::lcrTwoStopBits;
// A character's length at 19200 baud (52083.333 ns per bit): 8E1 is 11 bits, 7N2 is 10.
constexpr uint64_t kChar8E1Ns = 572917;
constexpr uint64_t kChar7N2Ns = 520833;
// The uptime counts in 8254 periods (838 ns), and each poll adds a few
// hundred instructions: emulated times are checked to within this much.
constexpr uint64_t kResolutionNs = 3000;
constexpr uint64_t kMillisecond = 1000000;
constexpr unsigned kFifoDepth = Uart16550::transmitFifoDepth;

uint8_t rd(uint8_t reg) { return arch_x86::portRead8(static_cast<uint16_t>(bsp::rs485PortAddress + reg)); }

void wr(uint8_t reg, uint8_t value) { arch_x86::portWrite8(static_cast<uint16_t>(bsp::rs485PortAddress + reg), value); }

bool near(uint64_t measured, uint64_t expected) { return measured + kResolutionNs >= expected && measured <= expected + kResolutionNs; }

/// Polls LSR until (LSR & mask) == value; false after timeoutNs. LSR reads clear its error bits,
/// which are kept in *seen.
bool waitLsr(uint8_t mask, uint8_t value, uint64_t timeoutNs, uint64_t* when = nullptr, uint8_t* seen = nullptr)
{
    const uint64_t deadline = timerAgent.Uptime() + timeoutNs;
    for (;;) {
        const uint64_t now = timerAgent.Uptime();
        const uint8_t lsr = rd(Uart16550::lineStatusRegister);
        if (seen != nullptr) {
            *seen |= lsr;
        }
        if ((lsr & mask) == value) {
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

/// 19200 baud, the given format, FIFOs on with the given trigger, loopback, every interrupt source enabled.
void setUp(uint8_t lcr, uint8_t trigger)
{
    wr(Uart16550::interruptEnableRegister, 0);
    wr(Uart16550::lineControlRegister, Uart16550::lcrDivisorLatchAccess);
    wr(Uart16550::divisorLatchLow, kDivisor19200);
    wr(Uart16550::divisorLatchHigh, 0);
    wr(Uart16550::lineControlRegister, lcr);
    wr(Uart16550::fifoControlRegister, static_cast<uint8_t>(Uart16550::fcrEnable | Uart16550::fcrResetReceiver
                                                             | Uart16550::fcrResetTransmitter | trigger));
    wr(Uart16550::modemControlRegister, Uart16550::mcrLoop);
    (void)rd(Uart16550::lineStatusRegister);
    (void)rd(Uart16550::modemStatusRegister);
}

uint8_t iir() { return rd(Uart16550::interruptIdentRegister); }

bool registers(shell::Shell& shell)
{
    bool ok = true;
    wr(Uart16550::scratchRegister, 0x5A);
    ok = check(shell, rd(Uart16550::scratchRegister) == 0x5A, "SCR reads back") && ok;
    wr(Uart16550::lineControlRegister, Uart16550::lcrDivisorLatchAccess);
    wr(Uart16550::divisorLatchLow, 0x34);
    wr(Uart16550::divisorLatchHigh, 0x12);
    ok = check(shell, rd(Uart16550::divisorLatchLow) == 0x34 && rd(Uart16550::divisorLatchHigh) == 0x12,
               "DLL and DLM read back with DLAB set") && ok;
    wr(Uart16550::lineControlRegister, kLcr8E1);
    ok = check(shell, rd(Uart16550::lineControlRegister) == kLcr8E1, "LCR reads back") && ok;
    ok = check(shell, rd(Uart16550::interruptEnableRegister) == 0, "IER, not DLM, with DLAB clear") && ok;
    const uint8_t lsr = rd(Uart16550::lineStatusRegister);
    shell.print("LSR %02x IIR %02x\r\n", lsr, iir());
    ok = check(shell, (lsr & (Uart16550::lsrTransmitterHoldingEmpty | Uart16550::lsrTransmitterEmpty
                              | Uart16550::lsrDataReady))
                          == (Uart16550::lsrTransmitterHoldingEmpty | Uart16550::lsrTransmitterEmpty),
               "THRE and TEMT, no data") && ok;
    // MSR in loopback: RTS drives CTS and DTR drives DSR, with their delta bits until MSR is read.
    wr(Uart16550::modemControlRegister, Uart16550::mcrLoop);
    (void)rd(Uart16550::modemStatusRegister);
    wr(Uart16550::modemControlRegister, Uart16550::mcrLoop | Uart16550::mcrRts | Uart16550::mcrDtr);
    const uint8_t msr = rd(Uart16550::modemStatusRegister);
    const uint8_t again = rd(Uart16550::modemStatusRegister);
    shell.print("MSR %02x then %02x\r\n", msr, again);
    ok = check(shell, msr == (kMsrCts | kMsrDsr | kMsrDeltaCts | kMsrDeltaDsr), "loopback: CTS, DSR and their deltas")
         && ok;
    ok = check(shell, again == (kMsrCts | kMsrDsr), "reading MSR clears its deltas") && ok;
    wr(Uart16550::modemControlRegister, 0);
    return ok;
}

bool timing(shell::Shell& shell)
{
    bool ok = true;
    setUp(kLcr8E1, Uart16550::fcrTrigger4);
    // THRE's interrupt: enabling ETBEI with the holding register empty raises it; reading IIR clears it.
    wr(Uart16550::interruptEnableRegister, Uart16550::ierTransmitterEmpty);
    const uint8_t thre = iir();
    const uint8_t none = iir();
    shell.print("IIR %02x then %02x\r\n", thre, none);
    ok = check(shell, thre == (kIirFifosOn | Uart16550::iirTransmitterEmpty), "IIR: transmitter empty") && ok;
    ok = check(shell, none == (kIirFifosOn | Uart16550::iirNoInterruptPending), "reading IIR cleared it") && ok;
    wr(Uart16550::interruptEnableRegister, Uart16550::ierReceivedData);

    // Three characters: the first goes to the shift register at once, so
    // THRE falls with the second and rises when the third starts; TEMT
    // rises at the third's last stop bit, three character times after the
    // first write; the receiver has them then.
    const uint64_t start = timerAgent.Uptime();
    wr(Uart16550::transmitHoldingRegister, 0x11);
    wr(Uart16550::transmitHoldingRegister, 0x22);
    wr(Uart16550::transmitHoldingRegister, 0x33);
    const uint8_t busy = rd(Uart16550::lineStatusRegister);
    uint64_t threAt = 0;
    uint64_t temtAt = 0;
    ok = check(shell, (busy & (Uart16550::lsrTransmitterHoldingEmpty | Uart16550::lsrTransmitterEmpty)) == 0,
               "THRE and TEMT clear while the FIFO holds characters") && ok;
    ok = check(shell, waitLsr(Uart16550::lsrTransmitterHoldingEmpty, Uart16550::lsrTransmitterHoldingEmpty,
                              10 * kMillisecond, &threAt), "THRE rises") && ok;
    ok = check(shell, waitLsr(Uart16550::lsrTransmitterEmpty, Uart16550::lsrTransmitterEmpty, 10 * kMillisecond,
                              &temtAt), "TEMT rises") && ok;
    shell.print("THRE after %llu ns, TEMT after %llu ns (character %llu ns)\r\n",
                static_cast<unsigned long long>(threAt - start), static_cast<unsigned long long>(temtAt - start),
                static_cast<unsigned long long>(kChar8E1Ns));
    ok = check(shell, near(threAt - start, 2 * kChar8E1Ns), "THRE when the third character starts") && ok;
    ok = check(shell, near(temtAt - start, 3 * kChar8E1Ns), "TEMT at the third character's stop bit") && ok;
    // Below the trigger level of 4: no data interrupt, but DR; then the character time-out.
    const uint8_t before = iir();
    ok = check(shell, (rd(Uart16550::lineStatusRegister) & Uart16550::lsrDataReady) != 0, "DR with 3 characters")
         && ok;
    ok = check(shell, before == (kIirFifosOn | Uart16550::iirNoInterruptPending), "no interrupt below the trigger")
         && ok;
    uint8_t timeout = 0;
    uint64_t timeoutAt = 0;
    const uint64_t deadline = temtAt + 10 * kChar8E1Ns;
    while (timerAgent.Uptime() < deadline) {
        timeout = iir();
        if ((timeout & Uart16550::iirIdentMask) == Uart16550::iirCharacterTimeout) {
            timeoutAt = timerAgent.Uptime();
            break;
        }
    }
    shell.print("IIR %02x after %llu ns without a character\r\n", timeout,
                static_cast<unsigned long long>(timeoutAt - temtAt));
    ok = check(shell, timeout == (kIirFifosOn | Uart16550::iirCharacterTimeout)
                          && near(timeoutAt - temtAt, 4 * kChar8E1Ns),
               "the character time-out after four character times") && ok;
    const uint8_t a = rd(Uart16550::receiveBufferRegister);
    const uint8_t b = rd(Uart16550::receiveBufferRegister);
    const uint8_t c = rd(Uart16550::receiveBufferRegister);
    ok = check(shell, a == 0x11 && b == 0x22 && c == 0x33, "the characters come back in order") && ok;
    ok = check(shell, (rd(Uart16550::lineStatusRegister) & Uart16550::lsrDataReady) == 0
                          && iir() == (kIirFifosOn | Uart16550::iirNoInterruptPending),
               "reading the FIFO empty clears DR and the time-out") && ok;

    // Four characters reach the trigger: the data interrupt.
    for (uint8_t i = 0; i < 4; ++i) {
        wr(Uart16550::transmitHoldingRegister, i);
    }
    ok = check(shell, waitLsr(Uart16550::lsrTransmitterEmpty, Uart16550::lsrTransmitterEmpty, 10 * kMillisecond),
               "four characters sent") && ok;
    ok = check(shell, iir() == (kIirFifosOn | Uart16550::iirReceivedData), "IIR: data at the trigger level of 4")
         && ok;
    wr(Uart16550::fifoControlRegister,
       static_cast<uint8_t>(Uart16550::fcrEnable | Uart16550::fcrResetReceiver | Uart16550::fcrTrigger4));
    ok = check(shell, (rd(Uart16550::lineStatusRegister) & Uart16550::lsrDataReady) == 0, "FCR clears the receiver")
         && ok;

    // Another format: 7N2 is 10 bits, and 7 data bits keep the low 7 of the byte written.
    setUp(kLcr7N2, Uart16550::fcrTrigger1);
    const uint64_t sevenStart = timerAgent.Uptime();
    wr(Uart16550::transmitHoldingRegister, 0xFF);
    ok = check(shell, waitLsr(Uart16550::lsrTransmitterEmpty, Uart16550::lsrTransmitterEmpty, 10 * kMillisecond,
                              &temtAt), "7N2 character sent") && ok;
    shell.print("7N2: TEMT after %llu ns\r\n", static_cast<unsigned long long>(temtAt - sevenStart));
    ok = check(shell, near(temtAt - sevenStart, kChar7N2Ns), "a 7N2 character lasts 10 bits") && ok;
    ok = check(shell, rd(Uart16550::receiveBufferRegister) == 0x7F, "7 data bits") && ok;
    wr(Uart16550::modemControlRegister, 0);
    wr(Uart16550::interruptEnableRegister, 0);
    return ok;
}

bool overrun(shell::Shell& shell)
{
    bool ok = true;
    setUp(kLcr8E1, Uart16550::fcrTrigger14);
    // Seventeen characters into a 16-character FIFO nobody reads: the last is lost, OE is set.
    uint8_t seen = 0;
    for (unsigned i = 0; i <= kFifoDepth; ++i) {
        ok = check(shell, waitLsr(Uart16550::lsrTransmitterHoldingEmpty, Uart16550::lsrTransmitterHoldingEmpty,
                                  10 * kMillisecond, nullptr, &seen), "room in the transmit FIFO") && ok;
        wr(Uart16550::transmitHoldingRegister, static_cast<uint8_t>(0x40 + i));
    }
    ok = check(shell, waitLsr(Uart16550::lsrTransmitterEmpty, Uart16550::lsrTransmitterEmpty, 20 * kMillisecond,
                              nullptr, &seen), "seventeen characters sent") && ok;
    // The overrun may have been seen by a poll already (reading LSR clears OE): one more read tells.
    seen |= rd(Uart16550::lineStatusRegister);
    const uint8_t after = rd(Uart16550::lineStatusRegister);
    shell.print("LSR saw %02x, then %02x\r\n", seen, after);
    ok = check(shell, (seen & Uart16550::lsrOverrunError) != 0, "OE on the seventeenth character") && ok;
    ok = check(shell, (after & Uart16550::lsrOverrunError) == 0 && (after & kLsrFifoError) == 0,
               "reading LSR clears OE; no character carries an error") && ok;
    bool inOrder = true;
    for (unsigned i = 0; i < kFifoDepth; ++i) {
        inOrder = rd(Uart16550::receiveBufferRegister) == 0x40 + i && inOrder;
    }
    ok = check(shell, inOrder, "the sixteen stored characters are the first sixteen") && ok;
    ok = check(shell, (rd(Uart16550::lineStatusRegister) & Uart16550::lsrDataReady) == 0, "and nothing else") && ok;
    wr(Uart16550::modemControlRegister, 0);
    return ok;
}

bool rs485UartModel(shell::Shell& shell)
{
    bool ok = registers(shell);
    ok = timing(shell) && ok;
    ok = overrun(shell) && ok;
    return ok;
}

} // namespace

DCOS_TARGET_TEST(rs485UartModelTest, "rs485uart",
                 "RS-485 UART model: registers, loopback timing, trigger and time-out interrupts, overrun",
                 rs485UartModel);

} // namespace target_test
