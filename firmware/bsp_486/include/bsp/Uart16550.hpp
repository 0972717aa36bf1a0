// Interrupt-driven driver for a National Semiconductor PC16550D UART.
//
// Register and bit names follow the PC16550D datasheet, Table II ("Summary
// of Registers") and the register descriptions that follow it.
//
// Reception and transmission both run through ring buffers filled and
// drained by the interrupt handler. Nothing received is ever dropped by the
// driver: when the receive ring is full the handler stops taking bytes and
// disables the receive interrupt, leaving further bytes in the chip's FIFO
// (and, on a link with flow control, in the sender) until the reader makes
// room. A writer that finds the transmit ring full waits for space.
#pragma once

#include <stdint.h>

#include <arch_x86/IoWindow.hpp>
#include <dcos/Status.hpp>
#include <runtime/Format.hpp>
#include <runtime/RingBuffer.hpp>

namespace bsp {

class Uart16550 final : public runtime::CharacterSink {
public:
    // Register offsets (DLAB = 0 unless noted).
    static constexpr uint8_t receiveBufferRegister = 0;   // RBR, read
    static constexpr uint8_t transmitHoldingRegister = 0; // THR, write
    static constexpr uint8_t interruptEnableRegister = 1; // IER
    static constexpr uint8_t interruptIdentRegister = 2;  // IIR, read
    static constexpr uint8_t fifoControlRegister = 2;     // FCR, write
    static constexpr uint8_t lineControlRegister = 3;     // LCR
    static constexpr uint8_t modemControlRegister = 4;    // MCR
    static constexpr uint8_t lineStatusRegister = 5;      // LSR
    static constexpr uint8_t modemStatusRegister = 6;     // MSR
    static constexpr uint8_t scratchRegister = 7;         // SCR
    static constexpr uint8_t divisorLatchLow = 0;         // DLL, DLAB = 1
    static constexpr uint8_t divisorLatchHigh = 1;        // DLM, DLAB = 1

    // IER bits.
    static constexpr uint8_t ierReceivedData = 1u << 0;      // ERBFI
    static constexpr uint8_t ierTransmitterEmpty = 1u << 1;  // ETBEI
    static constexpr uint8_t ierLineStatus = 1u << 2;        // ELSI
    // IIR: bit 0 clear means an interrupt is pending; bits 3-1 identify it.
    static constexpr uint8_t iirNoInterruptPending = 1u << 0;
    static constexpr uint8_t iirIdentMask = 0x0E;
    static constexpr uint8_t iirLineStatus = 0x06;
    static constexpr uint8_t iirReceivedData = 0x04;
    static constexpr uint8_t iirCharacterTimeout = 0x0C;
    static constexpr uint8_t iirTransmitterEmpty = 0x02;
    static constexpr uint8_t iirModemStatus = 0x00;
    // FCR bits.
    static constexpr uint8_t fcrEnable = 1u << 0;
    static constexpr uint8_t fcrResetReceiver = 1u << 1;
    static constexpr uint8_t fcrResetTransmitter = 1u << 2;
    static constexpr uint8_t fcrTrigger8 = 2u << 6;   // receive trigger level 8 bytes
    // LCR bits.
    static constexpr uint8_t lcrWordLength8 = 3u << 0; // WLS1 WLS0
    static constexpr uint8_t lcrDivisorLatchAccess = 1u << 7; // DLAB
    // MCR bits. On PC boards OUT2 gates the UART's interrupt onto the bus.
    static constexpr uint8_t mcrDtr = 1u << 0;
    static constexpr uint8_t mcrRts = 1u << 1;
    static constexpr uint8_t mcrOut2 = 1u << 3;
    static constexpr uint8_t mcrLoop = 1u << 4;
    // LSR bits.
    static constexpr uint8_t lsrDataReady = 1u << 0;
    static constexpr uint8_t lsrOverrunError = 1u << 1;
    static constexpr uint8_t lsrParityError = 1u << 2;
    static constexpr uint8_t lsrFramingError = 1u << 3;
    static constexpr uint8_t lsrBreak = 1u << 4;
    static constexpr uint8_t lsrTransmitterHoldingEmpty = 1u << 5; // THRE
    static constexpr uint8_t lsrTransmitterEmpty = 1u << 6;        // TEMT
    /// Bound on polls of the line status while flushing: far longer than a
    /// byte takes at any baud rate, so only a dead UART reaches it.
    static constexpr uint32_t maximumFlushPolls = 1000000;

    /// The 16550's transmit FIFO depth: bytes that may be written per THRE.
    static constexpr unsigned transmitFifoDepth = 16;
    /// The reference clock divided by 16: the baud rate for divisor 1.
    static constexpr uint32_t maximumBaud = 115200;
    /// Ring buffer sizes. The receive ring is deliberately small: a line
    /// editor consumes bytes as they come, and the chip's FIFO plus
    /// interrupt masking absorb bursts without loss.
    static constexpr unsigned receiveRingSize = 64;
    static constexpr unsigned transmitRingSize = 256;

    /// Upper bound on events handled in one interrupt, so a babbling line
    /// cannot hold the CPU inside the handler.
    static constexpr unsigned maximumEventsPerInterrupt = 32;

    /// Error counters, for diagnostics.
    struct Statistics {
        uint32_t overrunErrors;
        uint32_t parityErrors;
        uint32_t framingErrors;
        uint32_t breaks;
        uint32_t receiveThrottled; ///< Times the receive ring filled up.
    };

    explicit Uart16550(arch_x86::IoWindow window) : window_(window) {}

    /// Checks that a UART answers at the window (via the scratch register),
    /// then programs baud, 8N1, FIFOs and the receive interrupts. Returns
    /// NotFound when no UART is present, InvalidArgument for a baud rate
    /// that does not divide the reference clock.
    dcos::Status initialise(uint32_t baud);

    /// Interrupt handler body: services received data, line status and
    /// transmitter-empty events, at most maximumEventsPerInterrupt.
    void handleInterrupt();

    /// Takes one received byte; false when none is waiting.
    bool read(char& character);

    /// True when a received byte is waiting.
    bool hasInput() const { return !receiveRing_.empty(); }

    /// Queues one byte for transmission, waiting while the ring is full.
    /// With interrupts disabled it drains the ring by polling instead.
    void put(char character) override;

    /// Drains the transmit ring by polling and waits until the transmitter
    /// shift register is empty, so the last byte is on the line.
    void flush();

    /// Writes a byte by polling, first draining whatever is queued so the
    /// output stays in order. For the panic path, where interrupts are off.
    void putPolled(char character);

    const Statistics& statistics() const { return statistics_; }

    /// Sets a function the interrupt handler calls after storing received bytes.
    void setReceiveNotifier(void (*notifier)(void*), void* context)
    {
        receiveNotifier_ = notifier;
        receiveNotifierContext_ = context;
    }

private:
    void writeByteWhenReady(char character);
    void enableInterruptBits(uint8_t bits);
    void disableInterruptBits(uint8_t bits);
    void serviceReceive();
    void serviceTransmit();
    void serviceEvents();

    arch_x86::IoWindow window_;
    runtime::RingBuffer<char, receiveRingSize> receiveRing_;
    runtime::RingBuffer<char, transmitRingSize> transmitRing_;
    volatile uint8_t interruptEnable_ = 0;
    Statistics statistics_{};
    void (*receiveNotifier_)(void*) = nullptr;
    void* receiveNotifierContext_ = nullptr;
};

} // namespace bsp
