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

#include <stddef.h>
#include <stdint.h>

#include <arch_x86/IoWindow.hpp>
#include <dcos/Status.hpp>
#include <runtime/Format.hpp>
#include <runtime/RingBuffer.hpp>

namespace bsp {

/// Parity of a port's characters (PC16550D, LCR bits 3 and 4).
enum class UartParity : uint8_t { None, Odd, Even };

/// How a port drives an RS-485 transceiver's driver enable.
enum class DriverEnable : uint8_t {
    None, ///< A point-to-point port: RTS stays asserted (flow control, as before).
    Rts,  ///< Half duplex: RTS asserted while transmitting, released on LSR.TEMT.
};

/// One port's configuration of the chip core.
struct UartSettings {
    uint32_t baud = 115200;
    uint8_t dataBits = 8;       ///< 5 to 8.
    UartParity parity = UartParity::None;
    uint8_t stopBits = 1;       ///< 1 or 2.
    uint8_t receiveTrigger = 8; ///< FIFO receive interrupt level: 1, 4, 8 or 14 bytes.
    DriverEnable driverEnable = DriverEnable::None;

    /// Bits per character on the line: start, data, parity, stop.
    constexpr unsigned characterBits() const
    {
        return 1u + dataBits + (parity != UartParity::None ? 1u : 0u) + stopBits;
    }
};

class Uart16550 final : public runtime::CharacterSink {
public:
    // Register offsets (datasheet Table II; DLAB = 0 unless noted).
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

    // IER bits (datasheet 8.7, "Interrupt Enable Register").
    static constexpr uint8_t ierReceivedData = 1u << 0;      // ERBFI
    static constexpr uint8_t ierTransmitterEmpty = 1u << 1;  // ETBEI
    static constexpr uint8_t ierLineStatus = 1u << 2;        // ELSI
    // IIR (datasheet 8.6 and Table IV): bit 0 clear means an interrupt is pending; bits 3-1 identify it.
    static constexpr uint8_t iirNoInterruptPending = 1u << 0;
    static constexpr uint8_t iirIdentMask = 0x0E;
    static constexpr uint8_t iirLineStatus = 0x06;
    static constexpr uint8_t iirReceivedData = 0x04;
    static constexpr uint8_t iirCharacterTimeout = 0x0C;
    static constexpr uint8_t iirTransmitterEmpty = 0x02;
    static constexpr uint8_t iirModemStatus = 0x00;
    // FCR bits (datasheet 8.5, "FIFO Control Register"). Bits 7-6 are the
    // receiver FIFO's interrupt trigger level.
    static constexpr uint8_t fcrEnable = 1u << 0;
    static constexpr uint8_t fcrResetReceiver = 1u << 1;
    static constexpr uint8_t fcrResetTransmitter = 1u << 2;
    static constexpr uint8_t fcrTrigger1 = 0u << 6;   // receive trigger level 1 byte
    static constexpr uint8_t fcrTrigger4 = 1u << 6;   // receive trigger level 4 bytes
    static constexpr uint8_t fcrTrigger8 = 2u << 6;   // receive trigger level 8 bytes
    static constexpr uint8_t fcrTrigger14 = 3u << 6;  // receive trigger level 14 bytes
    // LCR bits (datasheet 8.1, "Line Control Register").
    static constexpr uint8_t lcrWordLength5 = 0u << 0; // WLS1 WLS0: 5 + the field's value bits
    static constexpr uint8_t lcrWordLength8 = 3u << 0; // WLS1 WLS0
    static constexpr uint8_t lcrTwoStopBits = 1u << 2; // STB
    static constexpr uint8_t lcrParityEnable = 1u << 3; // PEN
    static constexpr uint8_t lcrEvenParity = 1u << 4;   // EPS
    static constexpr uint8_t lcrDivisorLatchAccess = 1u << 7; // DLAB
    // MCR bits (datasheet 8.8, "Modem Control Register"). On PC boards OUT2 gates the UART's interrupt onto the bus.
    static constexpr uint8_t mcrDtr = 1u << 0;
    static constexpr uint8_t mcrRts = 1u << 1;
    static constexpr uint8_t mcrOut2 = 1u << 3;
    static constexpr uint8_t mcrLoop = 1u << 4;
    // LSR bits (datasheet 8.4, "Line Status Register"). THRE: the holding
    // register (FIFO) is empty; TEMT: it and the transmitter shift register are.
    static constexpr uint8_t lsrDataReady = 1u << 0;
    static constexpr uint8_t lsrOverrunError = 1u << 1;
    static constexpr uint8_t lsrParityError = 1u << 2;
    static constexpr uint8_t lsrFramingError = 1u << 3;
    static constexpr uint8_t lsrBreak = 1u << 4;
    /// The bits that say the character at the top of the FIFO is damaged.
    static constexpr uint8_t lsrCharacterErrors = lsrParityError | lsrFramingError | lsrBreak;
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

    /// Receives each byte in the interrupt, on a port with a receive sink;
    /// @p damaged: the line status said it came with a parity or framing
    /// error or as a break (PC16550D 8.6.3, LSR bits 2 to 4), which a
    /// protocol must not take as good data.
    using ReceiveSink = void (*)(void* context, uint8_t byte, bool damaged);

    explicit Uart16550(arch_x86::IoWindow window) : window_(window) {}

    /// Checks that a UART answers at the window (via the scratch register),
    /// then programs the port's settings, FIFOs and the receive interrupts.
    /// Returns NotFound when no UART is present, InvalidArgument for a baud
    /// rate that does not divide the reference clock or a line format or
    /// trigger level the chip does not have.
    dcos::Status initialise(const UartSettings& settings);

    /// The console's settings (8N1, trigger level 8, no driver enable) at @p baud.
    dcos::Status initialise(uint32_t baud) { return initialise(UartSettings{.baud = baud}); }

    /// Stops the port: no interrupts, RTS released, rings emptied. Its
    /// owner detaches the interrupt line first.
    void shutdown();

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
    const UartSettings& settings() const { return settings_; }

    /// Starts sending @p length bytes as one transmission: on an RS-485 port
    /// RTS (the driver enable) is asserted first. Busy while the previous
    /// transmission is still going (see finishTransmission), InvalidArgument
    /// for nothing or more than the transmit ring holds. Does not wait.
    dcos::Status transmit(const uint8_t* bytes, size_t length);

    /// Whether a transmission started by transmit() is still going.
    bool transmitting() const { return transmitting_; }

    /// Ends a transmission whose bytes have all left the FIFO once the last
    /// one has left the shift register (LSR.TEMT): releases RTS on an
    /// RS-485 port and returns true; false while the shift register still
    /// holds it (call again later, after about a character time) or while
    /// bytes are still queued. True when no transmission is going. Never waits.
    bool finishTransmission();

    /// Sets the function the interrupt handler calls when a transmission's
    /// last byte has been handed to the shift register (the FIFO is empty),
    /// so that its owner calls finishTransmission().
    void setTransmitNotifier(void (*notifier)(void*), void* context)
    {
        transmitNotifier_ = notifier;
        transmitNotifierContext_ = context;
    }

    /// Hands every received byte to @p sink in the interrupt instead of the
    /// receive ring (null: back to the ring).
    void setReceiveSink(ReceiveSink sink, void* context)
    {
        receiveSinkContext_ = context;
        receiveSink_ = sink;
    }

    /// Whether RTS is asserted now (on an RS-485 port: the driver is on).
    bool driverEnabled() const { return (modemControl_ & mcrRts) != 0; }

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
    void setModemControl(uint8_t value);
    bool releaseDriverIfDone();

    arch_x86::IoWindow window_;
    UartSettings settings_{};
    volatile uint8_t modemControl_ = 0;
    volatile bool transmitting_ = false;
    // The last byte of a transmission is in the shift register: the FIFO
    // is empty and THRE's interrupt is off, so only TEMT is left to wait for.
    volatile bool draining_ = false;
    ReceiveSink receiveSink_ = nullptr;
    void* receiveSinkContext_ = nullptr;
    void (*transmitNotifier_)(void*) = nullptr;
    void* transmitNotifierContext_ = nullptr;
    runtime::RingBuffer<char, receiveRingSize> receiveRing_;
    runtime::RingBuffer<char, transmitRingSize> transmitRing_;
    volatile uint8_t interruptEnable_ = 0;
    Statistics statistics_{};
    void (*receiveNotifier_)(void*) = nullptr;
    void* receiveNotifierContext_ = nullptr;
};

} // namespace bsp
