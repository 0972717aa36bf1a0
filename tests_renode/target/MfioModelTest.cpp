// The emulator's multi-function I/O board model (isa-mfio), register by
// register, from the controller: raw 16-bit port I/O, no driver. The
// contract is docs/iobus/mfio-register-map.md; the board file wires the
// board at 0x300, IRQ 5, in loopback (DAC n to ADC n, DO to DI).
//
// mfiodump is not a check of the map but a probe the host-side tests read:
// it prints codes, digital inputs, the conversion time and the interrupt
// count in a fixed format, and the emulator tests run it with fault, noise
// and plant properties (tests_renode/test_isa_mfio_model.py).
#include "KernelTestSupport.hpp"

#include <dcos/SystemAgent.hpp>
#include <dcos/TimerAgent.hpp>

#include <arch_x86/PortIo.hpp>

namespace target_test {

namespace {

using dcos::Status;
using dcos::systemAgent;
using dcos::taskAgent;
using dcos::timerAgent;

constexpr uint16_t kBase = 0x300;
constexpr unsigned kLine = 5;

// Register offsets.
constexpr uint16_t kId = 0x00;
constexpr uint16_t kRevision = 0x02;
constexpr uint16_t kControl = 0x04;
constexpr uint16_t kStatus = 0x06;
constexpr uint16_t kAdcStart = 0x08;
constexpr uint16_t kAdcData = 0x0A;
constexpr uint16_t kGain = 0x0C;
constexpr uint16_t kIrqAck = 0x0E;
constexpr uint16_t kDi = 0x10;
constexpr uint16_t kDo = 0x12;
constexpr uint16_t kDac0 = 0x20;

constexpr uint16_t kIdValue = 0x4D46;
constexpr uint16_t kRevisionValue = 0x0100;
constexpr uint16_t kIrqEnable = 0x0001;
constexpr uint16_t kReset = 0x8000;
constexpr uint16_t kBusy = 0x0001;
constexpr uint16_t kDone = 0x0002;
constexpr uint16_t kOverrange = 0x0004;
constexpr uint16_t kIrqPending = 0x0008;
constexpr uint16_t kDataOverrange = 0x8000;

constexpr unsigned kChannels = 8;
constexpr uint64_t kMicrosecond = 1000;
constexpr uint64_t kMillisecond = 1000000;
constexpr uint64_t kConversionNs = 20 * kMicrosecond;

uint16_t readRegister(uint16_t offset) { return arch_x86::portRead16(static_cast<uint16_t>(kBase + offset)); }

void writeRegister(uint16_t offset, uint16_t value)
{
    arch_x86::portWrite16(static_cast<uint16_t>(kBase + offset), value);
}

uint32_t readRegister32(uint16_t offset)
{
    uint32_t value;
    asm volatile("inl %1, %0" : "=a"(value) : "Nd"(static_cast<uint16_t>(kBase + offset)) : "memory");
    return value;
}

uint16_t dacRegister(unsigned channel) { return static_cast<uint16_t>(kDac0 + 2 * channel); }

/// Checks the identification register and resets the board.
bool probeAndReset(shell::Shell& shell)
{
    const uint16_t id = readRegister(kId);
    if (id != kIdValue) {
        shell.print("no I/O board at 0x%x: ID reads %04x, expected %04x\r\n", kBase, id, kIdValue);
        return false;
    }
    writeRegister(kControl, kReset);
    return true;
}

/// Polls STATUS until BUSY clears; false after timeoutNs.
bool waitWhileBusy(uint64_t timeoutNs = 10 * kMillisecond)
{
    const uint64_t deadline = timerAgent.Uptime() + timeoutNs;
    while (readRegister(kStatus) & kBusy) {
        if (timerAgent.Uptime() > deadline) {
            return false;
        }
    }
    return true;
}

/// One polled conversion of channel at its current gain; data is ADC_DATA.
bool convert(shell::Shell& shell, unsigned channel, uint16_t& data)
{
    writeRegister(kIrqAck, 1);
    writeRegister(kAdcStart, static_cast<uint16_t>(channel));
    if (!waitWhileBusy()) {
        shell.print("channel %u: still BUSY after 10 ms\r\n", channel);
        return false;
    }
    if (!(readRegister(kStatus) & kDone)) {
        shell.print("channel %u: conversion ended without DONE (STATUS %04x)\r\n", channel, readRegister(kStatus));
        return false;
    }
    data = readRegister(kAdcData);
    return true;
}

/// The code the map gives for DAC code dac looped back at gain: the DAC's
/// volts times the gain through the converter, exact in loopback.
uint16_t expectedData(unsigned channel, uint16_t dac, unsigned gain)
{
    const int32_t code = (static_cast<int32_t>(dac) - 2048) * static_cast<int32_t>(gain) + 2048;
    const uint16_t channelBits = static_cast<uint16_t>(channel << 12);
    if (code < 0) {
        return static_cast<uint16_t>(channelBits | kDataOverrange);
    }
    if (code > 4095) {
        return static_cast<uint16_t>(channelBits | kDataOverrange | 4095);
    }
    return static_cast<uint16_t>(channelBits | code);
}

/// Converts channel with dac on its output and checks the exact result.
bool checkLoopback(shell::Shell& shell, unsigned channel, uint16_t dac, unsigned gain)
{
    writeRegister(dacRegister(channel), dac);
    uint16_t data = 0;
    if (!convert(shell, channel, data)) {
        return false;
    }
    const uint16_t expected = expectedData(channel, dac, gain);
    const uint16_t status = readRegister(kStatus);
    const bool overrange = (expected & kDataOverrange) != 0;
    if (data != expected || ((status & kOverrange) != 0) != overrange) {
        shell.print("channel %u gain %u DAC %03x: ADC_DATA %04x STATUS %04x, expected %04x with OVERRANGE %s\r\n",
                    channel, gain, dac, data, status, expected, overrange ? "set" : "clear");
        return false;
    }
    return true;
}

// -- registers --------------------------------------------------------------

bool registers(shell::Shell& shell)
{
    if (!probeAndReset(shell)) {
        return false;
    }
    bool ok = check(shell, readRegister(kRevision) == kRevisionValue, "REVISION is 1.0");

    // Reset values.
    ok = check(shell, readRegister(kControl) == 0, "CONTROL resets to 0") && ok;
    ok = check(shell, readRegister(kStatus) == 0, "STATUS resets to 0") && ok;
    ok = check(shell, readRegister(kGain) == 0, "GAIN resets to 0") && ok;
    ok = check(shell, readRegister(kDo) == 0, "DO resets to 0") && ok;
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        ok = check(shell, readRegister(dacRegister(channel)) == 0x800, "DAC resets to 0x800") && ok;
    }

    // Read/write registers read back; only the defined bits are kept.
    writeRegister(kControl, 0x7FFF);
    ok = check(shell, readRegister(kControl) == kIrqEnable, "CONTROL keeps only IRQ_ENABLE") && ok;
    writeRegister(kControl, 0);
    writeRegister(kGain, 0xE4B1);
    ok = check(shell, readRegister(kGain) == 0xE4B1, "GAIN reads back") && ok;
    writeRegister(kDo, 0xA55A);
    ok = check(shell, readRegister(kDo) == 0xA55A, "DO reads back") && ok;
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        writeRegister(dacRegister(channel), static_cast<uint16_t>(0xF000 | (0x111 * (channel + 1))));
    }
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        ok = check(shell, readRegister(dacRegister(channel)) == 0x111 * (channel + 1),
                   "a DAC keeps bits 11:0") && ok;
    }

    // Read-only registers ignore writes; write-only ones read as 0.
    writeRegister(kId, 0);
    writeRegister(kRevision, 0);
    writeRegister(kStatus, 0xFFFF);
    writeRegister(kAdcData, 0xFFFF);
    ok = check(shell, readRegister(kId) == kIdValue && readRegister(kRevision) == kRevisionValue,
               "ID and REVISION ignore writes") && ok;
    ok = check(shell, readRegister(kStatus) == 0 && readRegister(kAdcData) == 0, "STATUS and ADC_DATA ignore writes")
         && ok;
    ok = check(shell, readRegister(kAdcStart) == 0 && readRegister(kIrqAck) == 0, "ADC_START and IRQ_ACK read 0")
         && ok;

    // RESET restores every register and clears itself.
    writeRegister(kControl, kIrqEnable);
    writeRegister(kControl, kReset | kIrqEnable);
    ok = check(shell, readRegister(kControl) == 0, "RESET clears itself and CONTROL") && ok;
    ok = check(shell, readRegister(kGain) == 0 && readRegister(kDo) == 0, "RESET clears GAIN and DO") && ok;
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        ok = check(shell, readRegister(dacRegister(channel)) == 0x800, "RESET sets the DACs to 0x800") && ok;
    }

    // 8-bit accesses are not decoded: reads see 0xFF, writes do nothing.
    ok = check(shell, arch_x86::portRead8(kBase + kId) == 0xFF && arch_x86::portRead8(kBase + kId + 1) == 0xFF,
               "byte reads of ID return 0xFF") && ok;
    ok = check(shell, arch_x86::portRead8(kBase + kDo) == 0xFF, "a byte read of DO returns 0xFF") && ok;
    writeRegister(kDo, 0x1234);
    arch_x86::portWrite8(kBase + kDo, 0x56);
    arch_x86::portWrite8(kBase + kDo + 1, 0x78);
    ok = check(shell, readRegister(kDo) == 0x1234, "byte writes to DO are ignored") && ok;
    arch_x86::portWrite8(kBase + kAdcStart, 0);
    ok = check(shell, (readRegister(kStatus) & kBusy) == 0, "a byte write to ADC_START starts nothing") && ok;
    // Nor are 32-bit accesses or 16-bit ones at odd offsets (not in the map:
    // the model treats them like byte accesses).
    ok = check(shell, readRegister32(kId) == 0xFFFFFFFFu, "a 32-bit read of ID returns all ones") && ok;
    ok = check(shell, arch_x86::portRead16(kBase + kId + 1) == 0xFFFF, "a 16-bit read at an odd offset returns 0xFFFF")
         && ok;
    arch_x86::portWrite16(kBase + kDo + 1, 0xFFFF);
    ok = check(shell, readRegister(kDo) == 0x1234, "a 16-bit write at an odd offset is ignored") && ok;
    shell.print("ID %04x, REVISION %04x\r\n", readRegister(kId), readRegister(kRevision));
    writeRegister(kControl, kReset);
    return ok;
}

DCOS_TARGET_TEST(mfioRegistersTest, "mfioreg", "I/O board model: ID, REVISION, reset values, read-back, 8-bit access",
                 registers);

// -- digital loopback ---------------------------------------------------------

bool digitalLoopback(shell::Shell& shell)
{
    if (!probeAndReset(shell)) {
        return false;
    }
    bool ok = check(shell, readRegister(kDi) == 0, "DI follows DO after reset");
    unsigned failures = 0;
    for (unsigned bit = 0; bit < 16; ++bit) {
        const uint16_t one = static_cast<uint16_t>(1u << bit);
        const uint16_t zero = static_cast<uint16_t>(~one);
        writeRegister(kDo, one);
        const uint16_t seenOne = readRegister(kDi);
        writeRegister(kDo, zero);
        const uint16_t seenZero = readRegister(kDi);
        if (seenOne != one || seenZero != zero) {
            shell.print("bit %u: DO %04x gave DI %04x, DO %04x gave DI %04x\r\n", bit, one, seenOne, zero, seenZero);
            ++failures;
        }
    }
    ok = check(shell, failures == 0, "walking ones and zeros from DO to DI") && ok;
    writeRegister(kDo, 0xC3A5);
    ok = check(shell, readRegister(kDi) == 0xC3A5 && readRegister(kDo) == 0xC3A5, "DI equals DO") && ok;
    shell.print("walked 32 patterns, %u failed\r\n", failures);
    writeRegister(kControl, kReset);
    return ok;
}

DCOS_TARGET_TEST(mfioDigitalTest, "mfiodio", "I/O board model: DO drives DI in loopback, walking ones and zeros",
                 digitalLoopback);

// -- analog loopback at gain 1 ---------------------------------------------------

bool analogLoopback(shell::Shell& shell)
{
    if (!probeAndReset(shell)) {
        return false;
    }
    bool ok = true;
    // Every channel gets a different code, so a crossed channel shows.
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        writeRegister(dacRegister(channel), static_cast<uint16_t>(0x123 + 0x1F1 * channel));
    }
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        uint16_t data = 0;
        ok = convert(shell, channel, data) && ok;
        const uint16_t expected = static_cast<uint16_t>((channel << 12) | (0x123 + 0x1F1 * channel));
        if (data != expected) {
            shell.print("channel %u: ADC_DATA %04x, expected %04x\r\n", channel, data, expected);
            ok = false;
        }
    }
    // The ends and the middle of the range, on every channel.
    static constexpr uint16_t codes[] = {0x000, 0x001, 0x7FF, 0x800, 0x801, 0xFFE, 0xFFF};
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        for (uint16_t code : codes) {
            ok = checkLoopback(shell, channel, code, 1) && ok;
        }
    }
    shell.print("8 channels at gain 1: %s\r\n", ok ? "every code exact" : "mismatches above");
    writeRegister(kControl, kReset);
    return ok;
}

DCOS_TARGET_TEST(mfioAnalogTest, "mfioadc", "I/O board model: DAC n drives ADC n at gain 1 with the exact code",
                 analogLoopback);

// -- gains, saturation and the overrange flag ------------------------------------

struct GainCase {
    unsigned gainIndex;
    int16_t offset; // DAC code minus 0x800
};

bool gains(shell::Shell& shell)
{
    if (!probeAndReset(shell)) {
        return false;
    }
    static constexpr unsigned gainOf[4] = {1, 10, 100, 1000};
    // Each gain just inside and just outside full scale, both ways.
    static constexpr GainCase cases[] = {
        {0, 0},   {0, 1},    {0, -1},    {0, 2047},  {0, -2048},
        {1, 0},   {1, 1},    {1, -1},    {1, 204},   {1, -204},  {1, 205}, {1, -205}, {1, 2047}, {1, -2048},
        {2, 0},   {2, 1},    {2, -1},    {2, 20},    {2, -20},   {2, 21},  {2, -21},
        {3, 0},   {3, 1},    {3, -1},    {3, 2},     {3, -2},    {3, 3},   {3, -3},
    };
    bool ok = true;
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        for (const GainCase& c : cases) {
            writeRegister(kGain, static_cast<uint16_t>(c.gainIndex << (2 * channel)));
            ok = checkLoopback(shell, channel, static_cast<uint16_t>(0x800 + c.offset), gainOf[c.gainIndex]) && ok;
        }
    }
    ok = check(shell, ok, "every gain, in and out of range, on every channel") && ok;

    // The overrange flag follows the last result.
    writeRegister(kGain, 3);
    ok = checkLoopback(shell, 0, 0x805, 1000) && ok;
    ok = check(shell, (readRegister(kStatus) & kOverrange) && (readRegister(kAdcData) & kDataOverrange),
               "a saturated result sets OVERRANGE and ADC_DATA bit 15") && ok;
    ok = checkLoopback(shell, 0, 0x800, 1000) && ok;
    ok = check(shell, !(readRegister(kStatus) & kOverrange), "the next in-range result clears OVERRANGE") && ok;

    // Each channel has its own two bits: channel n at gain n mod 4.
    uint16_t gainWord = 0;
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        gainWord = static_cast<uint16_t>(gainWord | ((channel % 4) << (2 * channel)));
    }
    writeRegister(kGain, gainWord);
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        ok = checkLoopback(shell, channel, 0x801, gainOf[channel % 4]) && ok;
    }
    shell.print("GAIN %04x: channel n converts 0x801 at gain n mod 4: %s\r\n", gainWord, ok ? "exact" : "wrong");
    writeRegister(kControl, kReset);
    return ok;
}

DCOS_TARGET_TEST(mfioGainTest, "mfiogain", "I/O board model: each gain, per channel, saturation and OVERRANGE", gains);

// -- conversion timing, BUSY and DONE --------------------------------------------

bool timing(shell::Shell& shell)
{
    if (!probeAndReset(shell)) {
        return false;
    }
    // BUSY at once, still BUSY half-way, DONE after the conversion time.
    writeRegister(dacRegister(3), 0x321);
    const uint64_t start = timerAgent.Uptime();
    writeRegister(kAdcStart, 3);
    const uint16_t atStart = readRegister(kStatus);
    spin(kConversionNs / 2);
    const uint16_t halfWay = readRegister(kStatus);
    const bool finished = waitWhileBusy();
    const uint64_t elapsed = timerAgent.Uptime() - start;
    const uint16_t atEnd = readRegister(kStatus);
    shell.print("STATUS %04x at start, %04x half-way, %04x at the end; conversion took %llu ns\r\n", atStart, halfWay,
                atEnd, static_cast<unsigned long long>(elapsed));
    bool ok = check(shell, atStart == kBusy, "BUSY and not DONE as the conversion starts");
    ok = check(shell, halfWay == kBusy, "still BUSY half-way") && ok;
    ok = check(shell, finished && atEnd == kDone, "DONE and not BUSY at the end") && ok;
    // The clock is read through the 8254 (838 ns steps) and the poll loop
    // adds a few microseconds.
    ok = check(shell, elapsed >= kConversionNs - 1000 && elapsed <= kConversionNs + 15 * kMicrosecond,
               "the conversion takes 20 us of emulated time") && ok;
    ok = check(shell, readRegister(kAdcData) == 0x3321, "the result of channel 3") && ok;

    // DONE is latched: reading the data does not clear it, IRQ_ACK does.
    readRegister(kAdcData);
    ok = check(shell, readRegister(kStatus) == kDone, "reading ADC_DATA leaves DONE") && ok;
    writeRegister(kIrqAck, 0);
    ok = check(shell, readRegister(kStatus) == kDone, "IRQ_ACK without bit 0 leaves DONE") && ok;
    writeRegister(kIrqAck, 1);
    ok = check(shell, readRegister(kStatus) == 0, "IRQ_ACK clears DONE") && ok;
    ok = check(shell, readRegister(kAdcData) == 0x3321, "IRQ_ACK leaves ADC_DATA") && ok;

    // A start while BUSY is ignored: the running conversion finishes as started.
    writeRegister(dacRegister(1), 0x111);
    writeRegister(dacRegister(2), 0x222);
    writeRegister(kAdcStart, 1);
    spin(kConversionNs / 2);
    writeRegister(kAdcStart, 2);
    const uint64_t secondStart = timerAgent.Uptime();
    ok = check(shell, waitWhileBusy(), "the conversion ends") && ok;
    const uint64_t remaining = timerAgent.Uptime() - secondStart;
    ok = check(shell, readRegister(kAdcData) == 0x1111, "ADC_START while BUSY is ignored") && ok;
    ok = check(shell, remaining <= kConversionNs / 2 + 10 * kMicrosecond,
               "the ignored start does not lengthen the conversion") && ok;

    // The sample is taken at the start: a DAC change during BUSY is not seen.
    writeRegister(kIrqAck, 1);
    writeRegister(kAdcStart, 1);
    writeRegister(dacRegister(1), 0x999);
    ok = check(shell, waitWhileBusy() && readRegister(kAdcData) == 0x1111, "the input is sampled at the start") && ok;

    // No interrupt enabled: DONE without IRQ_PENDING.
    ok = check(shell, (readRegister(kStatus) & kIrqPending) == 0, "no IRQ_PENDING with IRQ_ENABLE clear") && ok;
    writeRegister(kControl, kReset);
    return ok;
}

DCOS_TARGET_TEST(mfioTimingTest, "mfiotiming", "I/O board model: BUSY, DONE, 20 us conversions, starts while busy",
                 timing);

// -- the conversion-complete interrupt --------------------------------------------

struct IrqRecord {
    volatile unsigned count;
    volatile uint16_t statusSeen;
    volatile uint16_t dataSeen;
    volatile bool acknowledge;
};

IrqRecord irqRecord;

void mfioIsr(void* context)
{
    IrqRecord& record = *static_cast<IrqRecord*>(context);
    record.statusSeen = readRegister(kStatus);
    record.dataSeen = readRegister(kAdcData);
    if (record.acknowledge) {
        writeRegister(kIrqAck, 1);
    }
    record.count = record.count + 1;
}

/// Waits (sleeping) until the ISR has run count times in all; false after 100 ms.
bool waitForIrqs(unsigned count)
{
    const uint64_t deadline = timerAgent.Uptime() + 100 * kMillisecond;
    while (irqRecord.count < count) {
        if (timerAgent.Uptime() > deadline) {
            return false;
        }
        (void)taskAgent.SleepFor(kMillisecond);
    }
    return true;
}

bool interrupts(shell::Shell& shell)
{
    if (!probeAndReset(shell)) {
        return false;
    }
    irqRecord.count = 0;
    irqRecord.acknowledge = false;
    Status installed = systemAgent.InstallISR(kLine, mfioIsr, &irqRecord);
    if (!checkStatus(shell, installed, Status::Ok, "InstallISR on line 5 (is another driver on it?)")) {
        return false;
    }
    bool ok = true;

    // IRQ_ENABLE clear: the conversion completes silently.
    writeRegister(dacRegister(5), 0x555);
    writeRegister(kAdcStart, 5);
    ok = check(shell, waitWhileBusy(), "conversion without interrupts ends") && ok;
    (void)taskAgent.SleepFor(2 * kMillisecond);
    ok = check(shell, irqRecord.count == 0 && readRegister(kStatus) == kDone, "no interrupt with IRQ_ENABLE clear")
         && ok;
    writeRegister(kIrqAck, 1);

    // IRQ_ENABLE set: the completion raises IRQ 5 and IRQ_PENDING; the
    // request stays until IRQ_ACK.
    writeRegister(kControl, kIrqEnable);
    writeRegister(kAdcStart, 5);
    ok = check(shell, waitForIrqs(1), "the conversion raises IRQ 5") && ok;
    shell.print("ISR saw STATUS %04x ADC_DATA %04x\r\n", irqRecord.statusSeen, irqRecord.dataSeen);
    ok = check(shell, irqRecord.statusSeen == (kDone | kIrqPending) && irqRecord.dataSeen == 0x5555,
               "the ISR sees DONE, IRQ_PENDING and the result") && ok;
    ok = check(shell, readRegister(kStatus) == (kDone | kIrqPending), "IRQ_PENDING stays until IRQ_ACK") && ok;
    writeRegister(kIrqAck, 1);
    ok = check(shell, readRegister(kStatus) == 0, "IRQ_ACK clears DONE and IRQ_PENDING") && ok;

    // An ISR that acknowledges gets one interrupt per conversion.
    irqRecord.acknowledge = true;
    constexpr unsigned kRounds = 5;
    for (unsigned round = 0; round < kRounds; ++round) {
        writeRegister(kAdcStart, static_cast<uint16_t>(round));
        ok = check(shell, waitForIrqs(2 + round), "one interrupt per conversion") && ok;
    }
    (void)taskAgent.SleepFor(2 * kMillisecond);
    shell.print("%u interrupts for %u conversions with IRQ_ENABLE\r\n", irqRecord.count, kRounds + 1);
    ok = check(shell, irqRecord.count == kRounds + 1, "exactly one interrupt each") && ok;
    ok = check(shell, readRegister(kStatus) == 0, "the ISR's IRQ_ACK left nothing pending") && ok;

    writeRegister(kControl, kReset);
    ok = checkStatus(shell, systemAgent.RemoveISR(kLine), Status::Ok, "RemoveISR") && ok;
    return ok;
}

DCOS_TARGET_TEST(mfioInterruptTest, "mfioirq", "I/O board model: IRQ_ENABLE raises IRQ 5, IRQ_ACK clears it",
                 interrupts);

// -- the probe the host-side tests read -------------------------------------------

bool dump(shell::Shell& shell)
{
    const uint16_t id = readRegister(kId);
    shell.print("MFIO id=%04x\r\n", id);
    if (!probeAndReset(shell)) {
        return false;
    }
    bool ok = true;
    writeRegister(kDo, 0x5A3C);
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        writeRegister(dacRegister(channel), static_cast<uint16_t>(0x400 + 0x100 * channel));
    }
    for (unsigned channel = 0; channel < kChannels; ++channel) {
        uint16_t data = 0;
        ok = convert(shell, channel, data) && ok;
        shell.print("MFIO adc ch=%u data=%04x status=%04x\r\n", channel, data, readRegister(kStatus));
    }
    for (unsigned round = 0; round < 8; ++round) {
        uint16_t data = 0;
        ok = convert(shell, 0, data) && ok;
        shell.print("MFIO repeat ch=0 data=%04x\r\n", data);
    }
    static constexpr uint16_t outputs[] = {0x5A3C, 0x0000, 0xFFFF};
    for (uint16_t value : outputs) {
        writeRegister(kDo, value);
        shell.print("MFIO dio do=%04x di=%04x\r\n", value, readRegister(kDi));
    }

    writeRegister(kIrqAck, 1);
    const uint64_t start = timerAgent.Uptime();
    writeRegister(kAdcStart, 7);
    ok = check(shell, waitWhileBusy(1000 * kMillisecond), "the timed conversion ends") && ok;
    shell.print("MFIO conversion ns=%llu\r\n", static_cast<unsigned long long>(timerAgent.Uptime() - start));

    irqRecord.count = 0;
    irqRecord.acknowledge = false;
    if (checkStatus(shell, systemAgent.InstallISR(kLine, mfioIsr, &irqRecord), Status::Ok, "InstallISR on line 5")) {
        writeRegister(kIrqAck, 1);
        writeRegister(kControl, kIrqEnable);
        writeRegister(kAdcStart, 0);
        ok = check(shell, waitWhileBusy(), "the interrupt conversion ends") && ok;
        (void)taskAgent.SleepFor(5 * kMillisecond);
        shell.print("MFIO irq count=%u status=%04x\r\n", irqRecord.count, readRegister(kStatus));
        writeRegister(kControl, kReset);
        ok = checkStatus(shell, systemAgent.RemoveISR(kLine), Status::Ok, "RemoveISR") && ok;
    } else {
        ok = false;
    }
    shell.print("MFIO end\r\n");
    return ok;
}

DCOS_TARGET_TEST(mfioDumpTest, "mfiodump", "I/O board model: prints codes, DI, timing and interrupts for host checks",
                 dump);

} // namespace

} // namespace target_test
