// The RTU transport ([SL] 2.5.1): an ADU is the address, the PDU and the
// CRC-16, framed on the line by silences (RtuReceiver).
#pragma once

#include <modbus/RtuReceiver.hpp>
#include <modbus/Transport.hpp>

namespace modbus {

class RtuTransport final : public Transport {
public:
    /// A transport for a line with @p timing (RtuTiming::make()).
    explicit RtuTransport(const RtuTiming& timing = RtuTiming{}) : receiver_(timing) {}

    /// Address 0..247, the PDU, then the CRC low byte first: PDU length + 3.
    ModbusResult<size_t> encode(uint8_t unit, const uint8_t* pdu, size_t length, uint8_t* out,
                                size_t capacity) override;
    void onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs) override { receiver_.onBytes(bytes, count, nowNs); }
    void poll(uint64_t nowNs) override { receiver_.poll(nowNs); }
    bool takeFrame(ReceivedFrame& frame) override;
    uint64_t nextDeadlineNs() const override { return receiver_.nextDeadlineNs(); }
    bool readyToSend() const override { return receiver_.idle(); }
    bool receiving() const override
    {
        return receiver_.state() == RtuReceiver::State::Reception
               || receiver_.state() == RtuReceiver::State::ControlAndWaiting;
    }
    void onTransmitDone(uint64_t nowNs) override { receiver_.restartSilence(nowNs); }
    /// See RtuReceiver::markLastCharacterDamaged(); the line's driver calls it
    /// for a character its UART flagged, right after the station was given it.
    void markLastCharacterDamaged() { receiver_.markLastCharacterDamaged(); }

    /// The receive state machine, for its counters and state.
    const RtuReceiver& receiver() const { return receiver_; }

private:
    RtuReceiver receiver_;
};

} // namespace modbus
