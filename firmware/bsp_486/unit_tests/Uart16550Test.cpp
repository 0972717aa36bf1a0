#include <bsp/Uart16550.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

#include <string>

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

} // namespace
