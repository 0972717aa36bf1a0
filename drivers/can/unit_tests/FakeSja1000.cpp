#include "FakeSja1000.hpp"

namespace sja1000_test {

namespace reg = sja1000::reg;

namespace {

// The frame buffer bytes of a frame, as the chip stores it (DS 6.4.13).
std::vector<uint8_t> bufferOf(const can::CanFrame& frame)
{
    std::vector<uint8_t> bytes;
    uint8_t information = frame.length();
    if (frame.isRemote()) {
        information |= reg::kFrameRemote;
    }
    if (frame.isExtended()) {
        bytes = {static_cast<uint8_t>(information | reg::kFrameExtended), static_cast<uint8_t>(frame.id() >> 21),
                 static_cast<uint8_t>(frame.id() >> 13), static_cast<uint8_t>(frame.id() >> 5),
                 static_cast<uint8_t>(frame.id() << 3)};
    } else {
        bytes = {information, static_cast<uint8_t>(frame.id() >> 3), static_cast<uint8_t>(frame.id() << 5)};
    }
    if (!frame.isRemote()) {
        for (uint8_t i = 0; i < frame.length(); ++i) {
            bytes.push_back(frame.byte(i));
        }
    }
    return bytes;
}

} // namespace

void FakeSja1000::raise(uint8_t bits)
{
    interrupt = static_cast<uint8_t>(interrupt | (bits & interruptEnable));
}

uint32_t FakeSja1000::read(uint16_t offset, int)
{
    const bool reset = (mode & reg::kModeReset) != 0;
    switch (offset) {
    case reg::kMode: return mode;
    case reg::kStatus: return status;
    case reg::kInterrupt: {
        const uint8_t value = interrupt;
        // Reading clears every bit but RI, which follows the FIFO (DS 6.4.6).
        interrupt = static_cast<uint8_t>(fifo.empty() ? 0 : (interrupt & reg::kInterruptReceive));
        return value;
    }
    case reg::kInterruptEnable: return interruptEnable;
    case reg::kBusTiming0: return btr0;
    case reg::kBusTiming1: return btr1;
    case reg::kOutputControl: return outputControl;
    case reg::kErrorCodeCapture: return errorCode;
    case reg::kErrorWarningLimit: return errorWarningLimit;
    case reg::kRxErrorCounter: return rxErrors;
    case reg::kTxErrorCounter: return txErrors;
    case reg::kRxMessageCounter: return static_cast<uint16_t>(fifo.size());
    case reg::kClockDivider: return clockDivider;
    default: break;
    }
    if (offset >= reg::kFrameBuffer && offset < reg::kFrameBuffer + 13) {
        if (reset) {
            return offset < reg::kFrameBuffer + 8 ? acceptance[offset - reg::kFrameBuffer] : 0;
        }
        if (fifo.empty()) {
            return 0;
        }
        const std::vector<uint8_t>& front = fifo.front();
        const size_t index = offset - reg::kFrameBuffer;
        return index < front.size() ? front[index] : 0;
    }
    return 0;
}

void FakeSja1000::write(uint16_t offset, uint32_t value16, int)
{
    const uint8_t value = static_cast<uint8_t>(value16);
    const bool reset = (mode & reg::kModeReset) != 0;
    switch (offset) {
    case reg::kMode:
        if (resetModeIgnored) {
            mode = reg::kModeReset;
        } else {
            mode = value;
            if ((value & reg::kModeReset) == 0) {
                status = static_cast<uint8_t>(status & ~reg::kStatusBusOff);
            }
        }
        return;
    case reg::kCommand:
        if ((value & reg::kCommandReleaseBuffer) != 0 && !fifo.empty()) {
            ++releases;
            fifo.pop_front();
            if (fifo.empty()) {
                status = static_cast<uint8_t>(status & ~reg::kStatusReceiveBuffer);
                interrupt = static_cast<uint8_t>(interrupt & ~reg::kInterruptReceive);
            }
        }
        if ((value & reg::kCommandClearOverrun) != 0) {
            status = static_cast<uint8_t>(status & ~reg::kStatusDataOverrun);
        }
        if ((value & (reg::kCommandTransmit | reg::kCommandSelfReception)) != 0 && !reset) {
            ++transmissionRequests;
            transmitPending = true;
            selfReception = (value & reg::kCommandSelfReception) != 0;
            singleShot = (value & reg::kCommandAbort) != 0;
            status = static_cast<uint8_t>((status & ~(reg::kStatusTransmitBuffer | reg::kStatusTransmitComplete)) |
                                          reg::kStatusTransmitting);
        } else if ((value & reg::kCommandAbort) != 0 && transmitPending) {
            // The test's bus has not started the frame: the abort takes it back.
            ++aborts;
            transmitPending = false;
            status = static_cast<uint8_t>((status | reg::kStatusTransmitBuffer) &
                                          ~(reg::kStatusTransmitComplete | reg::kStatusTransmitting));
            raise(reg::kInterruptTransmit);
        }
        return;
    case reg::kInterruptEnable: interruptEnable = value; return;
    case reg::kClockDivider: clockDivider = value; return;
    default: break;
    }
    if (reset) {
        switch (offset) {
        case reg::kBusTiming0: btr0 = value; return;
        case reg::kBusTiming1: btr1 = value; return;
        case reg::kOutputControl: outputControl = value; return;
        case reg::kErrorWarningLimit: errorWarningLimit = value; return;
        case reg::kRxErrorCounter: rxErrors = value; return;
        case reg::kTxErrorCounter: txErrors = value; return;
        default: break;
        }
        if (offset >= reg::kAcceptanceCode0 && offset < reg::kAcceptanceCode0 + 8) {
            acceptance[offset - reg::kAcceptanceCode0] = value;
        }
        return;
    }
    if (offset >= reg::kFrameBuffer && offset < reg::kFrameBuffer + 13) {
        transmitBuffer[offset - reg::kFrameBuffer] = value;
    }
}

can::CanFrame FakeSja1000::transmitted() const
{
    const uint8_t information = transmitBuffer[0];
    const bool extended = (information & reg::kFrameExtended) != 0;
    const bool remote = (information & reg::kFrameRemote) != 0;
    const uint8_t length = information & reg::kFrameLengthMask;
    const uint32_t id = extended ? (uint32_t{transmitBuffer[1]} << 21) | (uint32_t{transmitBuffer[2]} << 13) |
                                       (uint32_t{transmitBuffer[3]} << 5) | (uint32_t{transmitBuffer[4]} >> 3)
                                 : (uint32_t{transmitBuffer[1]} << 3) | (uint32_t{transmitBuffer[2]} >> 5);
    const can::IdFormat format = extended ? can::IdFormat::Extended : can::IdFormat::Standard;
    const uint8_t* data = transmitBuffer + (extended ? reg::kExtendedDataOffset : reg::kStandardDataOffset);
    return remote ? can::CanFrame::makeRemote(id, format, length).value()
                  : can::CanFrame::makeData(id, format, data, length).value();
}

void FakeSja1000::completeTransmission()
{
    transmitPending = false;
    status = static_cast<uint8_t>((status | reg::kStatusTransmitBuffer | reg::kStatusTransmitComplete) &
                                  ~reg::kStatusTransmitting);
    raise(reg::kInterruptTransmit);
}

void FakeSja1000::receive(const can::CanFrame& frame)
{
    fifo.push_back(bufferOf(frame));
    status = static_cast<uint8_t>(status | reg::kStatusReceiveBuffer);
    raise(reg::kInterruptReceive);
}

void FakeSja1000::receiveRaw(uint8_t information, const std::vector<uint8_t>& identifierAndData)
{
    std::vector<uint8_t> bytes{information};
    bytes.insert(bytes.end(), identifierAndData.begin(), identifierAndData.end());
    fifo.push_back(bytes);
    status = static_cast<uint8_t>(status | reg::kStatusReceiveBuffer);
    raise(reg::kInterruptReceive);
}

void FakeSja1000::acknowledgeError()
{
    const bool passive = txErrors >= reg::kErrorPassiveCount;
    // ISO 11898-1: an error-passive transmitter's ACK error does not count.
    if (!passive) {
        txErrors = static_cast<uint8_t>(txErrors + 8);
    }
    errorCode = reg::kEccSegmentAckSlot | static_cast<uint8_t>(reg::kEccErrorCodeOther << reg::kEccErrorCodeShift);
    raise(reg::kInterruptBusError);
    if (!passive && txErrors >= reg::kErrorPassiveCount) {
        raise(reg::kInterruptErrorPassive);
    }
    if (txErrors >= errorWarningLimit && (status & reg::kStatusError) == 0) {
        status = static_cast<uint8_t>(status | reg::kStatusError);
        raise(reg::kInterruptErrorWarning);
    }
}

void FakeSja1000::setCounters(uint8_t receive, uint8_t transmit)
{
    const bool wasPassive = rxErrors >= reg::kErrorPassiveCount || txErrors >= reg::kErrorPassiveCount;
    rxErrors = receive;
    txErrors = transmit;
    const bool passive = rxErrors >= reg::kErrorPassiveCount || txErrors >= reg::kErrorPassiveCount;
    if (passive != wasPassive) {
        raise(reg::kInterruptErrorPassive);
    }
    const bool warning = rxErrors >= errorWarningLimit || txErrors >= errorWarningLimit;
    if (warning != ((status & reg::kStatusError) != 0)) {
        status = static_cast<uint8_t>(warning ? status | reg::kStatusError : status & ~reg::kStatusError);
        raise(reg::kInterruptErrorWarning);
    }
}

void FakeSja1000::busOff()
{
    transmitPending = false;
    txErrors = 127; // DS 6.4.12: bus-off sets TXERR to 127 for the recovery count.
    status = static_cast<uint8_t>((status | reg::kStatusBusOff | reg::kStatusError | reg::kStatusTransmitBuffer) &
                                  ~(reg::kStatusTransmitting | reg::kStatusTransmitComplete));
    mode = static_cast<uint8_t>(mode | reg::kModeReset);
    raise(reg::kInterruptErrorWarning);
}

void FakeSja1000::overrun()
{
    status = static_cast<uint8_t>(status | reg::kStatusDataOverrun);
    raise(reg::kInterruptDataOverrun);
}

} // namespace sja1000_test
