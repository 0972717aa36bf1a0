#include <bsp/Uart16550.hpp>

#include <arch_x86/Cpu.hpp>

namespace bsp {

dcos::Status Uart16550::initialise(uint32_t baud)
{
    if (baud == 0 || baud > maximumBaud || maximumBaud % baud != 0) {
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

    interruptEnable_ = 0;
    window_.write8(interruptEnableRegister, 0);
    const uint16_t divisor = static_cast<uint16_t>(maximumBaud / baud);
    window_.write8(lineControlRegister, lcrDivisorLatchAccess);
    window_.write8(divisorLatchLow, static_cast<uint8_t>(divisor & 0xFF));
    window_.write8(divisorLatchHigh, static_cast<uint8_t>(divisor >> 8));
    window_.write8(lineControlRegister, lcrWordLength8); // 8 data bits, no parity, 1 stop bit
    window_.write8(fifoControlRegister, fcrEnable | fcrResetReceiver | fcrResetTransmitter | fcrTrigger8);
    window_.write8(modemControlRegister, mcrDtr | mcrRts | mcrOut2);
    // Clear any stale status before interrupts are enabled.
    (void)window_.read8(lineStatusRegister);
    (void)window_.read8(modemStatusRegister);
    while ((window_.read8(lineStatusRegister) & lsrDataReady) != 0) {
        (void)window_.read8(receiveBufferRegister);
    }
    enableInterruptBits(ierReceivedData | ierLineStatus);
    return dcos::Status::Ok;
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
        if ((window_.read8(lineStatusRegister) & lsrDataReady) == 0) {
            return;
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
    if (transmitRing_.empty()) {
        disableInterruptBits(ierTransmitterEmpty);
    }
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
