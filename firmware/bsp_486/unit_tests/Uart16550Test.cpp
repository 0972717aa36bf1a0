#include <bsp/Uart16550.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using port_io_mock::write8;
using Uart = bsp::Uart16550;

constexpr uint16_t base = 0x3F8;
constexpr uint16_t lsr = base + Uart::lineStatusRegister;
constexpr uint16_t iir = base + Uart::interruptIdentRegister;
constexpr uint16_t rbr = base + Uart::receiveBufferRegister;
constexpr uint16_t ier = base + Uart::interruptEnableRegister;

// Makes the scratch-register probe succeed.
void answerProbe()
{
    port_io_mock::queueRead(base + Uart::scratchRegister, 0x5A);
    port_io_mock::queueRead(base + Uart::scratchRegister, 0xA5);
}

bool wroteTo(const std::vector<port_io_mock::Access>& log, uint16_t port, uint8_t value)
{
    for (const auto& access : log) {
        if (access.write && access.port == port && access.value == value) {
            return true;
        }
    }
    return false;
}

TEST(Uart16550, MissingChipIsReportedAsNotFound)
{
    port_io_mock::reset();
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    EXPECT_EQ(uart.initialise(115200), dcos::Status::NotFound); // An empty bus reads 0xFF.
}

TEST(Uart16550, UnsupportedBaudIsRefused)
{
    port_io_mock::reset();
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    EXPECT_EQ(uart.initialise(0), dcos::Status::InvalidArgument);
    EXPECT_EQ(uart.initialise(100000), dcos::Status::InvalidArgument);
    EXPECT_EQ(uart.initialise(230400), dcos::Status::InvalidArgument);
    EXPECT_TRUE(port_io_mock::takeLog().empty());
}

TEST(Uart16550, InitialisationProgramsDivisorLineFifoAndInterrupts)
{
    port_io_mock::reset();
    answerProbe();
    port_io_mock::setDefaultRead(lsr, 0x60); // Transmitter empty, no data.
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    EXPECT_EQ(uart.initialise(9600), dcos::Status::Ok);
    const auto log = port_io_mock::takeLog();
    EXPECT_TRUE(wroteTo(log, base + 3, 0x80)) << "DLAB set";
    EXPECT_TRUE(wroteTo(log, base + 0, 12)) << "divisor 115200 / 9600 = 12";
    EXPECT_TRUE(wroteTo(log, base + 1, 0)) << port_io_mock::describe(log);
    EXPECT_TRUE(wroteTo(log, base + 3, 0x03)) << "8N1 with DLAB clear";
    EXPECT_TRUE(wroteTo(log, base + 2, 0x87)) << "FIFO on, both reset, trigger 8";
    EXPECT_TRUE(wroteTo(log, base + 4, 0x0B)) << "DTR, RTS, OUT2";
    EXPECT_EQ(log.back(), write8(ier, Uart::ierReceivedData | Uart::ierLineStatus));
}

TEST(Uart16550, ReceivedBytesReachTheReaderInOrder)
{
    port_io_mock::reset();
    answerProbe();
    port_io_mock::setDefaultRead(lsr, 0x60);
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    ASSERT_EQ(uart.initialise(115200), dcos::Status::Ok);
    port_io_mock::takeLog();

    port_io_mock::queueRead(iir, Uart::iirReceivedData);
    for (char c : std::string("hi!")) {
        port_io_mock::queueRead(lsr, 0x61);
        port_io_mock::queueRead(rbr, static_cast<uint8_t>(c));
    }
    port_io_mock::queueRead(lsr, 0x60);
    port_io_mock::queueRead(iir, Uart::iirNoInterruptPending);
    uart.handleInterrupt();
    std::string received;
    char c;
    while (uart.read(c)) {
        received += c;
    }
    EXPECT_EQ(received, "hi!");
}

TEST(Uart16550, FullReceiveRingThrottlesInsteadOfDropping)
{
    port_io_mock::reset();
    answerProbe();
    port_io_mock::setDefaultRead(lsr, 0x61); // Data always ready.
    port_io_mock::setDefaultRead(iir, Uart::iirReceivedData);
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    port_io_mock::setDefaultRead(lsr, 0x60);
    ASSERT_EQ(uart.initialise(115200), dcos::Status::Ok);
    port_io_mock::setDefaultRead(lsr, 0x61);
    port_io_mock::setDefaultRead(rbr, 'x');
    port_io_mock::takeLog();

    // Keep interrupting until the ring is full and the driver throttles.
    for (int i = 0; i < 20; ++i) {
        uart.handleInterrupt();
    }
    const auto log = port_io_mock::takeLog();
    int bytesTaken = 0;
    for (const auto& access : log) {
        bytesTaken += (!access.write && access.port == rbr) ? 1 : 0;
    }
    EXPECT_EQ(bytesTaken, static_cast<int>(Uart::receiveRingSize)) << "no byte read beyond what the ring holds";
    EXPECT_TRUE(wroteTo(log, ier, Uart::ierLineStatus)) << "receive interrupt disabled";
    EXPECT_GE(uart.statistics().receiveThrottled, 1u);

    // Reading makes room and re-enables reception.
    char c;
    ASSERT_TRUE(uart.read(c));
    EXPECT_TRUE(wroteTo(port_io_mock::takeLog(), ier, Uart::ierReceivedData | Uart::ierLineStatus));
}

TEST(Uart16550, InterruptHandlingIsBounded)
{
    port_io_mock::reset();
    answerProbe();
    port_io_mock::setDefaultRead(lsr, 0x60);
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    ASSERT_EQ(uart.initialise(115200), dcos::Status::Ok);
    // A chip that always claims a modem-status interrupt must not hang the handler.
    port_io_mock::setDefaultRead(iir, Uart::iirModemStatus);
    port_io_mock::takeLog();
    uart.handleInterrupt();
    int identReads = 0;
    for (const auto& access : port_io_mock::takeLog()) {
        identReads += (!access.write && access.port == iir) ? 1 : 0;
    }
    EXPECT_EQ(identReads, static_cast<int>(Uart::maximumEventsPerInterrupt));
}

TEST(Uart16550, LineErrorsAreCounted)
{
    port_io_mock::reset();
    answerProbe();
    port_io_mock::setDefaultRead(lsr, 0x60);
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    ASSERT_EQ(uart.initialise(115200), dcos::Status::Ok);
    port_io_mock::queueRead(iir, Uart::iirLineStatus);
    port_io_mock::queueRead(lsr, Uart::lsrOverrunError | Uart::lsrFramingError);
    port_io_mock::queueRead(iir, Uart::iirNoInterruptPending);
    uart.handleInterrupt();
    EXPECT_EQ(uart.statistics().overrunErrors, 1u);
    EXPECT_EQ(uart.statistics().framingErrors, 1u);
    EXPECT_EQ(uart.statistics().parityErrors, 0u);
}

TEST(Uart16550, TransmitQueuesAndTheInterruptDrainsSixteenAtATime)
{
    port_io_mock::reset();
    answerProbe();
    port_io_mock::setDefaultRead(lsr, 0x60);
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    ASSERT_EQ(uart.initialise(115200), dcos::Status::Ok);
    port_io_mock::takeLog();
    for (int i = 0; i < 20; ++i) {
        uart.put(static_cast<char>('a' + i));
    }
    // The first put enables the transmitter interrupt.
    EXPECT_TRUE(wroteTo(port_io_mock::takeLog(), ier,
                        Uart::ierReceivedData | Uart::ierLineStatus | Uart::ierTransmitterEmpty));
    port_io_mock::queueRead(iir, Uart::iirTransmitterEmpty);
    port_io_mock::queueRead(iir, Uart::iirTransmitterEmpty);
    port_io_mock::queueRead(iir, Uart::iirNoInterruptPending);
    uart.handleInterrupt();
    std::string sent;
    bool disabledWhenEmpty = false;
    for (const auto& access : port_io_mock::takeLog()) {
        if (access.write && access.port == base) {
            sent += static_cast<char>(access.value);
        }
        if (access.write && access.port == ier && (access.value & Uart::ierTransmitterEmpty) == 0) {
            disabledWhenEmpty = true;
        }
    }
    EXPECT_EQ(sent, "abcdefghijklmnopqrst");
    EXPECT_TRUE(disabledWhenEmpty);
}

TEST(Uart16550, PolledOutputFlushesTheQueueFirst)
{
    port_io_mock::reset();
    answerProbe();
    port_io_mock::setDefaultRead(lsr, 0x60);
    Uart uart(arch_x86::IoWindow::ports(base, 8));
    ASSERT_EQ(uart.initialise(115200), dcos::Status::Ok);
    uart.put('a');
    uart.put('b');
    port_io_mock::takeLog();
    uart.putPolled('!');
    std::string sent;
    for (const auto& access : port_io_mock::takeLog()) {
        if (access.write && access.port == base) {
            sent += static_cast<char>(access.value);
        }
    }
    EXPECT_EQ(sent, "ab!");
}

// -- the RS-485 port's settings of the same chip core ------------------------

constexpr uint16_t com2 = 0x2F8;
constexpr uint16_t com2Lsr = com2 + Uart::lineStatusRegister;
constexpr uint16_t com2Iir = com2 + Uart::interruptIdentRegister;
constexpr uint16_t com2Mcr = com2 + Uart::modemControlRegister;
constexpr uint16_t com2Ier = com2 + Uart::interruptEnableRegister;

// RTU's default line ([SL] 2.5.1): 19200 baud, 8 data bits, even parity,
// one stop bit; trigger level 1 so every byte is timed as it arrives.
constexpr bsp::UartSettings rs485Settings{.baud = 19200,
                                          .dataBits = 8,
                                          .parity = bsp::UartParity::Even,
                                          .stopBits = 1,
                                          .receiveTrigger = 1,
                                          .driverEnable = bsp::DriverEnable::Rts};

// An RS-485 port, initialised, with the log emptied.
void bringUpRs485(Uart& uart)
{
    port_io_mock::reset();
    port_io_mock::queueRead(com2 + Uart::scratchRegister, 0x5A);
    port_io_mock::queueRead(com2 + Uart::scratchRegister, 0xA5);
    port_io_mock::setDefaultRead(com2Lsr, Uart::lsrTransmitterHoldingEmpty | Uart::lsrTransmitterEmpty);
    ASSERT_EQ(uart.initialise(rs485Settings), dcos::Status::Ok);
    port_io_mock::takeLog();
}

std::string sentTo(const std::vector<port_io_mock::Access>& log, uint16_t port)
{
    std::string sent;
    for (const auto& access : log) {
        if (access.write && access.port == port) {
            sent += static_cast<char>(access.value);
        }
    }
    return sent;
}

TEST(Uart16550Rs485, SettingsProgramParityTriggerLevelAndAReleasedDriver)
{
    port_io_mock::reset();
    port_io_mock::queueRead(com2 + Uart::scratchRegister, 0x5A);
    port_io_mock::queueRead(com2 + Uart::scratchRegister, 0xA5);
    port_io_mock::setDefaultRead(com2Lsr, 0x60);
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    ASSERT_EQ(uart.initialise(rs485Settings), dcos::Status::Ok);
    const auto log = port_io_mock::takeLog();
    EXPECT_TRUE(wroteTo(log, com2 + 0, 6)) << "divisor 115200 / 19200 = 6";
    EXPECT_TRUE(wroteTo(log, com2 + 3, 0x1B)) << "8 data bits, parity enabled and even, 1 stop bit";
    EXPECT_TRUE(wroteTo(log, com2 + 2, 0x07)) << "FIFO on, both reset, trigger level 1";
    EXPECT_TRUE(wroteTo(log, com2Mcr, Uart::mcrDtr | Uart::mcrOut2)) << "RTS (driver enable) released";
    EXPECT_FALSE(uart.driverEnabled());
    EXPECT_EQ(rs485Settings.characterBits(), 11u);
}

TEST(Uart16550Rs485, TwoStopBitsAndOddParityAreProgrammed)
{
    port_io_mock::reset();
    port_io_mock::queueRead(com2 + Uart::scratchRegister, 0x5A);
    port_io_mock::queueRead(com2 + Uart::scratchRegister, 0xA5);
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    bsp::UartSettings settings = rs485Settings;
    settings.parity = bsp::UartParity::Odd;
    settings.stopBits = 2;
    settings.receiveTrigger = 14;
    ASSERT_EQ(uart.initialise(settings), dcos::Status::Ok);
    const auto log = port_io_mock::takeLog();
    EXPECT_TRUE(wroteTo(log, com2 + 3, 0x0F)) << "8 data bits, 2 stop bits, parity enabled and odd";
    EXPECT_TRUE(wroteTo(log, com2 + 2, 0xC7)) << "trigger level 14";
}

TEST(Uart16550Rs485, SettingsTheChipDoesNotHaveAreRefusedBeforeAnyAccess)
{
    port_io_mock::reset();
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    bsp::UartSettings settings = rs485Settings;
    settings.receiveTrigger = 2;
    EXPECT_EQ(uart.initialise(settings), dcos::Status::InvalidArgument);
    settings = rs485Settings;
    settings.dataBits = 9;
    EXPECT_EQ(uart.initialise(settings), dcos::Status::InvalidArgument);
    settings = rs485Settings;
    settings.stopBits = 3;
    EXPECT_EQ(uart.initialise(settings), dcos::Status::InvalidArgument);
    EXPECT_TRUE(port_io_mock::takeLog().empty());
}

TEST(Uart16550Rs485, DriverIsEnabledBeforeTheFirstByteAndReleasedOnTemtNotThre)
{
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    bringUpRs485(uart);
    int notified = 0;
    uart.setTransmitNotifier([](void* count) { ++*static_cast<int*>(count); }, &notified);
    const uint8_t frame[] = {0x11, 0x03, 0x00, 0x6B, 0x00, 0x03, 0x76, 0x87};
    ASSERT_EQ(uart.transmit(frame, sizeof frame), dcos::Status::Ok);
    auto log = port_io_mock::takeLog();
    ASSERT_EQ(log.size(), 2u) << port_io_mock::describe(log);
    EXPECT_EQ(log[0], write8(com2Mcr, Uart::mcrDtr | Uart::mcrRts | Uart::mcrOut2)) << "driver on first";
    EXPECT_EQ(log[1], write8(com2Ier, Uart::ierReceivedData | Uart::ierLineStatus | Uart::ierTransmitterEmpty));
    EXPECT_TRUE(uart.driverEnabled());
    EXPECT_EQ(uart.transmit(frame, sizeof frame), dcos::Status::Busy) << "one transmission at a time";

    // THRE: the frame goes into the FIFO; the interrupt stays on to learn when the FIFO runs dry.
    port_io_mock::queueRead(com2Iir, Uart::iirTransmitterEmpty);
    port_io_mock::queueRead(com2Lsr, Uart::lsrTransmitterHoldingEmpty | Uart::lsrTransmitterEmpty);
    port_io_mock::queueRead(com2Iir, Uart::iirNoInterruptPending);
    uart.handleInterrupt();
    log = port_io_mock::takeLog();
    EXPECT_EQ(sentTo(log, com2), std::string(reinterpret_cast<const char*>(frame), sizeof frame));
    EXPECT_EQ(sentTo(log, com2Ier), "") << "transmitter interrupt kept on";
    EXPECT_EQ(notified, 0);

    // THRE again: the FIFO is empty but the last byte is in the shift register (TEMT clear).
    port_io_mock::queueRead(com2Iir, Uart::iirTransmitterEmpty);
    port_io_mock::queueRead(com2Lsr, Uart::lsrTransmitterHoldingEmpty);
    port_io_mock::queueRead(com2Lsr, Uart::lsrTransmitterHoldingEmpty);
    port_io_mock::queueRead(com2Iir, Uart::iirNoInterruptPending);
    uart.handleInterrupt();
    log = port_io_mock::takeLog();
    EXPECT_EQ(sentTo(log, com2Mcr), "") << "RTS must stay on while the last stop bit is sent: "
                                        << port_io_mock::describe(log);
    EXPECT_EQ(sentTo(log, com2Ier), std::string(1, Uart::ierReceivedData | Uart::ierLineStatus));
    EXPECT_EQ(notified, 1);
    EXPECT_TRUE(uart.driverEnabled());
    EXPECT_TRUE(uart.transmitting());

    port_io_mock::queueRead(com2Lsr, Uart::lsrTransmitterHoldingEmpty);
    EXPECT_FALSE(uart.finishTransmission()) << "TEMT still clear";
    EXPECT_TRUE(uart.driverEnabled());
    port_io_mock::queueRead(com2Lsr, Uart::lsrTransmitterHoldingEmpty | Uart::lsrTransmitterEmpty);
    EXPECT_TRUE(uart.finishTransmission());
    log = port_io_mock::takeLog();
    EXPECT_EQ(log.back(), write8(com2Mcr, Uart::mcrDtr | Uart::mcrOut2)) << "driver released on TEMT";
    EXPECT_FALSE(uart.driverEnabled());
    EXPECT_FALSE(uart.transmitting());
    EXPECT_EQ(uart.transmit(frame, 2), dcos::Status::Ok) << "the next transmission may start";
}

TEST(Uart16550Rs485, AShiftRegisterAlreadyEmptyReleasesTheDriverInTheInterrupt)
{
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    bringUpRs485(uart);
    const uint8_t frame[] = {0x01, 0x02};
    ASSERT_EQ(uart.transmit(frame, sizeof frame), dcos::Status::Ok);
    port_io_mock::queueRead(com2Iir, Uart::iirTransmitterEmpty);
    port_io_mock::queueRead(com2Iir, Uart::iirTransmitterEmpty);
    port_io_mock::queueRead(com2Iir, Uart::iirNoInterruptPending);
    uart.handleInterrupt(); // LSR reads its default: THRE and TEMT.
    EXPECT_FALSE(uart.driverEnabled());
    EXPECT_FALSE(uart.transmitting());
    EXPECT_TRUE(uart.finishTransmission());
}

TEST(Uart16550Rs485, FinishingBeforeTheFifoRanDryLeavesTheDriverOn)
{
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    bringUpRs485(uart);
    const uint8_t frame[40] = {};
    ASSERT_EQ(uart.transmit(frame, sizeof frame), dcos::Status::Ok);
    EXPECT_FALSE(uart.finishTransmission()) << "bytes still queued, TEMT notwithstanding";
    EXPECT_TRUE(uart.driverEnabled());
    EXPECT_EQ(uart.transmit(frame, 0), dcos::Status::InvalidArgument);
    uint8_t tooLong[Uart::transmitRingSize + 1] = {};
    EXPECT_EQ(uart.transmit(tooLong, sizeof tooLong), dcos::Status::InvalidArgument);
}

TEST(Uart16550Rs485, ReceivedBytesGoToTheSinkNotTheRing)
{
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    bringUpRs485(uart);
    std::string sunk;
    uart.setReceiveSink([](void* text, uint8_t byte, bool) { *static_cast<std::string*>(text) += static_cast<char>(byte); },
                        &sunk);
    port_io_mock::queueRead(com2Iir, Uart::iirReceivedData);
    for (char c : std::string("\x11\x03")) {
        port_io_mock::queueRead(com2Lsr, 0x61);
        port_io_mock::queueRead(com2 + Uart::receiveBufferRegister, static_cast<uint8_t>(c));
    }
    port_io_mock::queueRead(com2Lsr, 0x60);
    port_io_mock::queueRead(com2Iir, Uart::iirNoInterruptPending);
    uart.handleInterrupt();
    EXPECT_EQ(sunk, "\x11\x03");
    EXPECT_FALSE(uart.hasInput());
}

// The line status interrupt comes first for a damaged character, and reading
// the status clears its error bits: the sink gets that character flagged
// there, and the next, good one unflagged; a damaged character met while
// draining the FIFO is flagged too.
TEST(Uart16550Rs485, DamagedCharactersReachTheSinkFlagged)
{
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    bringUpRs485(uart);
    std::vector<std::pair<uint8_t, bool>> sunk;
    uart.setReceiveSink(
        [](void* into, uint8_t byte, bool damaged) {
            static_cast<std::vector<std::pair<uint8_t, bool>>*>(into)->emplace_back(byte, damaged);
        },
        &sunk);
    port_io_mock::queueRead(com2Iir, Uart::iirLineStatus);
    port_io_mock::queueRead(com2Lsr, 0x61 | Uart::lsrParityError);
    port_io_mock::queueRead(com2 + Uart::receiveBufferRegister, 0x11);
    port_io_mock::queueRead(com2Iir, Uart::iirReceivedData);
    port_io_mock::queueRead(com2Lsr, 0x61);
    port_io_mock::queueRead(com2 + Uart::receiveBufferRegister, 0x03);
    port_io_mock::queueRead(com2Lsr, 0x61 | Uart::lsrFramingError);
    port_io_mock::queueRead(com2 + Uart::receiveBufferRegister, 0xFF);
    port_io_mock::queueRead(com2Lsr, 0x60);
    port_io_mock::queueRead(com2Iir, Uart::iirNoInterruptPending);
    uart.handleInterrupt();
    const std::vector<std::pair<uint8_t, bool>> expected{{0x11, true}, {0x03, false}, {0xFF, true}};
    EXPECT_EQ(sunk, expected);
    EXPECT_EQ(uart.statistics().parityErrors, 1u);
}

TEST(Uart16550Rs485, ShutdownSilencesThePortAndReleasesTheDriver)
{
    Uart uart(arch_x86::IoWindow::ports(com2, 8));
    bringUpRs485(uart);
    const uint8_t frame[] = {0x01, 0x02, 0x03};
    ASSERT_EQ(uart.transmit(frame, sizeof frame), dcos::Status::Ok);
    port_io_mock::takeLog();
    uart.shutdown();
    const auto log = port_io_mock::takeLog();
    EXPECT_TRUE(wroteTo(log, com2Ier, 0));
    EXPECT_TRUE(wroteTo(log, com2Mcr, Uart::mcrDtr));
    EXPECT_FALSE(uart.driverEnabled());
    EXPECT_FALSE(uart.transmitting());
}

} // namespace
