// The transport table: what the protocol code (Slave, Master) needs from the
// line below it, in the manner of libmodbus's backends.
//
// The protocol code deals in PDUs ([AP] 4.1): a function code and its data.
// A transport wraps a PDU into an ADU for its line (RTU: address, PDU, CRC;
// TCP, later: the MBAP header and the PDU), and turns received bytes into
// checked frames. The protocol code never sees a CRC, a timer of the line or
// a UART, so a TCP transport or another line plugs in underneath it without a
// change above. Like every part of the stack, a transport reads no clock and
// owns no thread: it is fed bytes with their time and polled with the time.
//
// The destructor is protected and not virtual: transports are static objects
// of a node and are never deleted through this interface.
#pragma once

#include <modbus/ModbusResult.hpp>

#include <stddef.h>
#include <stdint.h>

namespace modbus {

/// Room for the largest ADU of any transport: the 253-byte PDU behind a
/// 7-byte MBAP header ([AP] 4.1, TCP ADU of 260 bytes); RTU needs 256.
inline constexpr size_t kMaxAduLength = 260;

/// A received frame as the protocol code sees it.
struct ReceivedFrame {
    uint8_t unit = 0;              ///< The address (RTU) or unit identifier (TCP).
    const uint8_t* pdu = nullptr;  ///< The function code and its data.
    size_t length = 0;             ///< Bytes at pdu, at least 1.
};

class Transport {
public:
    /// Wraps the @p length bytes of @p pdu into an ADU for @p unit in @p out
    /// (of @p capacity bytes) and returns the ADU's length; InvalidSlaveAddress
    /// for a unit the line cannot address, FrameTooLong for an empty or too
    /// long PDU, BufferTooSmall when @p out is too small.
    virtual ModbusResult<size_t> encode(uint8_t unit, const uint8_t* pdu, size_t length, uint8_t* out,
                                        size_t capacity) = 0;

    /// Bytes received from the line at @p nowNs.
    virtual void onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs) = 0;

    /// Lets time pass up to @p nowNs.
    virtual void poll(uint64_t nowNs) = 0;

    /// Takes the next checked frame into @p frame and returns true, or false
    /// when none waits. The PDU stays valid until the next onBytes() or poll().
    virtual bool takeFrame(ReceivedFrame& frame) = 0;

    /// When poll() has something to do, or ~0 when nothing is timed.
    virtual uint64_t nextDeadlineNs() const = 0;

    /// Whether a frame may be sent now (RTU: the line has been silent for t3.5).
    virtual bool readyToSend() const = 0;

    /// Whether a frame is arriving right now, so that a waiting master lets
    /// it finish before it calls a time-out.
    virtual bool receiving() const = 0;

    /// The station's own ADU has left the line at @p nowNs.
    virtual void onTransmitDone(uint64_t nowNs) = 0;

protected:
    ~Transport() = default;
};

} // namespace modbus
