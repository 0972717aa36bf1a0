// The receiving side of an ISO 15765-2 connection, as a pure state machine.
//
// The caller feeds it every frame received on the connection's rxId and the
// time (a monotonic count of nanoseconds), transmits the flow control frames
// it emits, and calls poll() at nextDeadlineNs() or later. A message is
// assembled in the caller's buffer and reported complete with its length; it
// stays there until the next single or first frame is taken.
//
//     SF             -> complete
//     FF             -> FC CTS (BS, STmin of the configuration); wait for CF (N_Cr)
//     CF             -> checked against the expected sequence number; after BS of
//                       them, FC CTS again; complete after the last
//     FF too long    -> FC OVFLW, rejected with BufferOverflow
//
// Following ISO 15765-2 "Unexpected arrival of N_PDU", a single or first
// frame in the middle of a reception ends the old message (UnexpectedPdu)
// and starts the new one; a consecutive frame with the wrong sequence number
// (duplicated, lost or out of order) ends the reception (WrongSequenceNumber);
// flow control frames and frames the standard says to ignore (reserved
// N_PCItype, SF_DL 0 or beyond the frame, a first frame shorter than 8 bytes
// or announcing fewer than 8, an escaped FF_DL below 4096, a consecutive
// frame too short for the bytes it must carry, or one arriving when no
// message is being received) change nothing.
//
// N_Cr runs from the moment a flow control is emitted or a consecutive frame
// taken. The receiver does not wait for its flow control to be confirmed
// sent (N_Ar): a flow control stuck in the controller means no consecutive
// frame arrives, and N_Cr ends the reception just the same. The receiver
// never sends Wait frames: it has the whole buffer from the first frame on.
#pragma once

#include <can/IsoTpConfig.hpp>
#include <can/IsoTpStep.hpp>
#include <can/LinkResult.hpp>

#include <stddef.h>
#include <stdint.h>

namespace can {

class IsoTpReceiver {
public:
    /// What nextDeadlineNs() returns when nothing is timed.
    static constexpr uint64_t kNoDeadline = ~static_cast<uint64_t>(0);

    /// A receiver with no buffer; only a placeholder: it takes no frame.
    IsoTpReceiver() = default;

    /// A receiver for @p config assembling messages of up to @p capacity bytes
    /// (at most 4095 are used) in @p buffer, or why it cannot be made.
    static LinkResult<IsoTpReceiver> create(const IsoTpConfig& config, uint8_t* buffer, size_t capacity);

    /// A frame received on the connection.
    IsoTpStep onFrame(const CanFrame& frame, uint64_t nowNs);

    /// Lets time pass: ends the reception when N_Cr expired.
    IsoTpStep poll(uint64_t nowNs);

    /// When poll() has something to do, or kNoDeadline.
    uint64_t nextDeadlineNs() const { return receiving_ ? deadline_ : kNoDeadline; }

    /// Drops the reception in progress, if any, without a step.
    void abort() { receiving_ = false; }

    /// Whether no segmented message is being received.
    bool idle() const { return !receiving_; }

    /// The message buffer; a completed message's bytes are at its start.
    const uint8_t* buffer() const { return buffer_; }

private:
    IsoTpReceiver(const IsoTpConfig& config, uint8_t* buffer, uint16_t capacity, uint8_t stMin);

    LinkError expire(uint64_t nowNs);
    void takeSingleFrame(const CanFrame& frame, IsoTpStep& step);
    void takeFirstFrame(const CanFrame& frame, IsoTpStep& step, uint64_t nowNs);
    void takeConsecutiveFrame(const CanFrame& frame, IsoTpStep& step, uint64_t nowNs);
    CanFrame flowControl(FlowStatus status) const;
    static uint64_t after(uint64_t nowNs, uint64_t intervalNs);

    IsoTpConfig config_;
    uint8_t* buffer_ = nullptr;
    uint16_t capacity_ = 0;
    uint8_t stMin_ = 0;
    bool receiving_ = false;
    uint16_t expected_ = 0;
    uint16_t received_ = 0;
    uint8_t sequence_ = 0;
    uint8_t blockCount_ = 0;
    uint64_t deadline_ = kNoDeadline;
};

} // namespace can
