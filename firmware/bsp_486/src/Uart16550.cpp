#include <bsp/Uart16550.hpp>

#include <arch_x86/Cpu.hpp>

namespace bsp {

namespace {

// The FCR trigger field for a receive interrupt level, or 0xFF for a level
// the chip does not have (datasheet 8.5: 1, 4, 8 or 14 bytes).
uint8_t triggerField(uint8_t level)
{
    switch (level) {
    case 1: return Uart16550::fcrTrigger1;
    case 4: return Uart16550::fcrTrigger4;
    case 8: return Uart16550::fcrTrigger8;
    case 14: return Uart16550::fcrTrigger14;
    default: return 0xFF;
    }
}

} // namespace

dcos::Status Uart16550::initialise(const UartSettings& settings)
{
    const uint32_t baud = settings.baud;
    if (baud == 0 || baud > maximumBaud || maximumBaud % baud != 0) {
        return dcos::Status::InvalidArgument;
    }
    const uint8_t trigger = triggerField(settings.receiveTrigger);
    if (settings.dataBits < 5 || settings.dataBits > 8 || settings.stopBits < 1 || settings.stopBits > 2
        || trigger == 0xFF) {
        return dcos::Status::InvalidArgument;
    }
    // The scratch register holds whatever is written to it on every 16450
    // and 16550; an empty ISA slot reads back all ones.
    window_.write8(scratchRegister, 0x5A);
    if (window_.read8(scratchRegister) != 0x5A) {
        return dcos::Status::NotFound;
    }
    window_.write8(scratchRegister, 0xA5);
    if (window_.read8(scratchRegister) != 0xA5) {
        return dcos::Status::NotFound;
    }

    settings_ = settings;
    transmitting_ = false;
    draining_ = false;
    interruptEnable_ = 0;
    window_.write8(interruptEnableRegister, 0);
    const uint16_t divisor = static_cast<uint16_t>(maximumBaud / baud);
    window_.write8(lineControlRegister, lcrDivisorLatchAccess);
    window_.write8(divisorLatchLow, static_cast<uint8_t>(divisor & 0xFF));
    window_.write8(divisorLatchHigh, static_cast<uint8_t>(divisor >> 8));
    uint8_t lineControl = static_cast<uint8_t>(lcrWordLength5 + (settings.dataBits - 5));
    lineControl = static_cast<uint8_t>(lineControl | (settings.stopBits == 2 ? lcrTwoStopBits : 0));
    if (settings.parity != UartParity::None) {
        lineControl = static_cast<uint8_t>(lineControl | lcrParityEnable
                                           | (settings.parity == UartParity::Even ? lcrEvenParity : 0));
    }
    window_.write8(lineControlRegister, lineControl); // DLAB clear again
    window_.write8(fifoControlRegister, fcrEnable | fcrResetReceiver | fcrResetTransmitter | trigger);
    // An RS-485 port starts listening: its driver enable (RTS) is released
    // until it has something to send. A point-to-point port keeps RTS up.
    setModemControl(settings.driverEnable == DriverEnable::Rts ? mcrDtr | mcrOut2 : mcrDtr | mcrRts | mcrOut2);
    // Clear any stale status before interrupts are enabled.
    (void)window_.read8(lineStatusRegister);
    (void)window_.read8(modemStatusRegister);
    for (unsigned i = 0; i < transmitFifoDepth && (window_.read8(lineStatusRegister) & lsrDataReady) != 0; ++i) {
        (void)window_.read8(receiveBufferRegister);
    }
    enableInterruptBits(ierReceivedData | ierLineStatus);
    return dcos::Status::Ok;
}

void Uart16550::shutdown()
{
    arch_x86::InterruptGuard guard;
    interruptEnable_ = 0;
    window_.write8(interruptEnableRegister, 0);
    setModemControl(mcrDtr);
    transmitting_ = false;
    draining_ = false;
    char discarded;
    while (transmitRing_.pop(discarded)) {
    }
    while (receiveRing_.pop(discarded)) {
    }
}

void Uart16550::setModemControl(uint8_t value)
{
    modemControl_ = value;
    window_.write8(modemControlRegister, value);
}

void Uart16550::enableInterruptBits(uint8_t bits)
{
    arch_x86::InterruptGuard guard;
    interruptEnable_ = static_cast<uint8_t>(interruptEnable_ | bits);
    window_.write8(interruptEnableRegister, interruptEnable_);
}

void Uart16550::disableInterruptBits(uint8_t bits)
{
    arch_x86::InterruptGuard guard;
    interruptEnable_ = static_cast<uint8_t>(interruptEnable_ & ~bits);
    window_.write8(interruptEnableRegister, interruptEnable_);
}

void Uart16550::serviceReceive()
{
    for (unsigned i = 0; i < transmitFifoDepth; ++i) {
        const uint8_t status = window_.read8(lineStatusRegister);
        if ((status & lsrDataReady) == 0) {
            return;
        }
        if (receiveSink_ != nullptr) {
            // The error bits describe the character at the top of the FIFO,
            // the one read next (PC16550D 8.6.3); with the line status
            // interrupt enabled they were taken there already.
            receiveSink_(receiveSinkContext_, window_.read8(receiveBufferRegister), (status & lsrCharacterErrors) != 0);
            continue;
        }
        if (receiveRing_.full()) {
            // Leave the byte in the FIFO and stop listening until read()
            // makes room; the chip (and the sender) hold the rest.
            ++statistics_.receiveThrottled;
            disableInterruptBits(ierReceivedData);
            return;
        }
        receiveRing_.push(static_cast<char>(window_.read8(receiveBufferRegister)));
    }
}

void Uart16550::serviceTransmit()
{
    if ((window_.read8(lineStatusRegister) & lsrTransmitterHoldingEmpty) == 0) {
        return;
    }
    char character;
    unsigned written = 0;
    while (written < transmitFifoDepth && transmitRing_.pop(character)) {
        window_.write8(transmitHoldingRegister, static_cast<uint8_t>(character));
        ++written;
    }
    if (written != 0 || !transmitRing_.empty()) {
        if (transmitRing_.empty() && settings_.driverEnable == DriverEnable::None) {
            // A point-to-point port need not learn when the FIFO runs dry.
            disableInterruptBits(ierTransmitterEmpty);
        }
        return;
    }
    // THRE with nothing left to write: the FIFO is empty and the last byte
    // is in the shift register (or already gone). Only an RS-485 port keeps
    // the interrupt on to get here.
    disableInterruptBits(ierTransmitterEmpty);
    if (transmitting_) {
        draining_ = true;
        (void)releaseDriverIfDone();
        if (transmitNotifier_ != nullptr) {
            transmitNotifier_(transmitNotifierContext_);
        }
    }
}

bool Uart16550::releaseDriverIfDone()
{
    // The 16550 has no interrupt for TEMT (datasheet 8.7 lists none), so
    // the end of the last stop bit is polled here, once per call.
    if ((window_.read8(lineStatusRegister) & lsrTransmitterEmpty) == 0) {
        return false;
    }
    if (settings_.driverEnable == DriverEnable::Rts) {
        setModemControl(static_cast<uint8_t>(modemControl_ & ~mcrRts));
    }
    draining_ = false;
    transmitting_ = false;
    return true;
}

dcos::Status Uart16550::transmit(const uint8_t* bytes, size_t length)
{
    if (bytes == nullptr || length == 0 || length > transmitRingSize) {
        return dcos::Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    if (transmitting_ || !transmitRing_.empty()) {
        return dcos::Status::Busy;
    }
    transmitting_ = true;
    draining_ = false;
    if (settings_.driverEnable == DriverEnable::Rts) {
        // The driver is on before the start bit of the first byte.
        setModemControl(static_cast<uint8_t>(modemControl_ | mcrRts));
    }
    for (size_t i = 0; i < length; ++i) {
        (void)transmitRing_.push(static_cast<char>(bytes[i])); // Fits: checked against the ring's size above.
    }
    // Enabling ETBEI with THRE set raises the interrupt at once (datasheet
    // 8.6), which moves the first 16 bytes into the FIFO.
    enableInterruptBits(ierTransmitterEmpty);
    return dcos::Status::Ok;
}

bool Uart16550::finishTransmission()
{
    arch_x86::InterruptGuard guard;
    if (!transmitting_) {
        return true;
    }
    if (!draining_) {
        return false;
    }
    return releaseDriverIfDone();
}

void Uart16550::handleInterrupt()
{
    const size_t receivedBefore = receiveRing_.size();
    serviceEvents();
    if (receiveNotifier_ != nullptr && receiveRing_.size() != receivedBefore) {
        receiveNotifier_(receiveNotifierContext_);
    }
}

void Uart16550::serviceEvents()
{
    for (unsigned event = 0; event < maximumEventsPerInterrupt; ++event) {
        const uint8_t ident = window_.read8(interruptIdentRegister);
        if ((ident & iirNoInterruptPending) != 0) {
            return;
        }
        switch (ident & iirIdentMask) {
        case iirLineStatus: {
            const uint8_t status = window_.read8(lineStatusRegister);
            statistics_.overrunErrors += (status & lsrOverrunError) != 0 ? 1 : 0;
            statistics_.parityErrors += (status & lsrParityError) != 0 ? 1 : 0;
            statistics_.framingErrors += (status & lsrFramingError) != 0 ? 1 : 0;
            statistics_.breaks += (status & lsrBreak) != 0 ? 1 : 0;
            // Reading the line status cleared its error bits, which belong to
            // the character at the top of the FIFO: a sink gets that character
            // now, flagged, or it would later read as good.
            if (receiveSink_ != nullptr && (status & lsrDataReady) != 0 && (status & lsrCharacterErrors) != 0) {
                receiveSink_(receiveSinkContext_, window_.read8(receiveBufferRegister), true);
            }
            break;
        }
        case iirReceivedData:
        case iirCharacterTimeout:
            serviceReceive();
            if ((interruptEnable_ & ierReceivedData) == 0) {
                // Throttled: the data-ready condition would keep the
                // identification register busy; other events still count.
                serviceTransmit();
                return;
            }
            break;
        case iirTransmitterEmpty:
            serviceTransmit();
            break;
        case iirModemStatus:
        default:
            (void)window_.read8(modemStatusRegister);
            break;
        }
    }
}

bool Uart16550::read(char& character)
{
    if (!receiveRing_.pop(character)) {
        return false;
    }
    if ((interruptEnable_ & ierReceivedData) == 0) {
        enableInterruptBits(ierReceivedData); // Room again: resume reception.
    }
    return true;
}

void Uart16550::writeByteWhenReady(char character)
{
    while ((window_.read8(lineStatusRegister) & lsrTransmitterHoldingEmpty) == 0) {
    }
    window_.write8(transmitHoldingRegister, static_cast<uint8_t>(character));
}

void Uart16550::put(char character)
{
    while (!transmitRing_.push(character)) {
        if ((arch_x86::readEflags() & arch_x86::eflagsInterruptEnable) != 0) {
            // The transmitter interrupt will drain the ring; sleep until it does.
            arch_x86::haltUntilInterrupt();
        } else {
            // No interrupt can drain it: move one byte out by hand.
            char oldest;
            if (transmitRing_.pop(oldest)) {
                writeByteWhenReady(oldest);
            }
        }
    }
    if ((interruptEnable_ & ierTransmitterEmpty) == 0) {
        enableInterruptBits(ierTransmitterEmpty);
    }
}

void Uart16550::flush()
{
    arch_x86::InterruptGuard guard;
    char queued;
    while (transmitRing_.pop(queued)) {
        writeByteWhenReady(queued);
    }
    for (uint32_t poll = 0; poll < maximumFlushPolls; ++poll) {
        if ((window_.read8(lineStatusRegister) & lsrTransmitterEmpty) != 0) {
            return;
        }
    }
}

void Uart16550::putPolled(char character)
{
    char queued;
    while (transmitRing_.pop(queued)) {
        writeByteWhenReady(queued);
    }
    writeByteWhenReady(character);
}

} // namespace bsp
