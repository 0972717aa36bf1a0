// The sending side of an ISO 15765-2 connection, as a pure state machine.
//
// The sender owns no timer, no controller and no copy of the message: the
// caller starts a message, hands each frame the sender emits to the CAN
// controller, reports when the controller has sent it (onTransmitConfirmed),
// feeds it the frames received on the connection's rxId (onFrame takes the
// flow control frames and ignores the others) and calls poll() at
// nextDeadlineNs() or later. Time is a monotonic count of nanoseconds passed
// in by the caller, so the same code runs under the kernel's clock, a host
// tool's clock and a test's hand-made clock, and every time-out is exact.
//
//     start        -> SF, or FF                (then: wait for confirmation, N_As)
//     confirmation -> SF done; FF: wait for FC (N_Bs)
//     FC CTS       -> CF ... (STmin apart, each confirmed within N_As),
//                     BS of them, then wait for FC again (N_Bs); done after the last
//     FC WAIT      -> wait for FC again (N_Bs), at most maxWaitFrames in a row
//     FC OVFLW     -> aborted, BufferOverflow
//
// BS and STmin come from the first ContinueToSend of a message and hold for
// all of it. Linux's can-isotp likewise keeps those of the first flow
// control, so a DCOS node and a Linux host pace a message alike whatever
// later flow controls say. A reserved STmin counts as 127 ms (ISO
// 15765-2:2016 9.6.5.5). The first consecutive frame after a flow control
// goes out at once, the next ones STmin after the previous one was
// confirmed sent: STmin is the gap between frames on the bus.
#pragma once

#include <can/IsoTpConfig.hpp>
#include <can/IsoTpStep.hpp>
#include <can/LinkResult.hpp>

#include <stddef.h>
#include <stdint.h>

namespace can {

class IsoTpSender {
public:
    /// What nextDeadlineNs() returns when nothing is timed.
    static constexpr uint64_t kNoDeadline = ~static_cast<uint64_t>(0);

    /// An unconfigured sender; only a placeholder: start() refuses with InvalidConfiguration.
    IsoTpSender() = default;

    /// A sender for the connection @p config describes, or why it cannot be made.
    static LinkResult<IsoTpSender> create(const IsoTpConfig& config);

    /// Begins sending @p length bytes from @p message, which must stay
    /// unchanged until the transfer completes or aborts. The step carries the
    /// single or first frame. Refused with Busy while a transfer runs, and
    /// with InvalidMessageLength for 0 bytes or more than 4095.
    IsoTpStep start(const uint8_t* message, size_t length, uint64_t nowNs);

    /// The controller has put the last emitted frame on the bus.
    IsoTpStep onTransmitConfirmed(uint64_t nowNs);

    /// A frame received on the connection; only flow control is taken.
    IsoTpStep onFrame(const CanFrame& frame, uint64_t nowNs);

    /// Lets time pass: sends a consecutive frame whose separation time is
    /// over, or ends the transfer when N_As or N_Bs expired.
    IsoTpStep poll(uint64_t nowNs);

    /// When poll() has something to do, or kNoDeadline.
    uint64_t nextDeadlineNs() const;

    /// Drops the transfer in progress, if any, without a step: the caller gave up.
    void abort();

    /// Whether no transfer is in progress.
    bool idle() const { return state_ == State::Idle; }

private:
    enum class State : uint8_t {
        Idle,
        AwaitingConfirmation, ///< A frame was emitted; N_As runs.
        AwaitingFlowControl,  ///< After the first frame or a full block; N_Bs runs.
        Separating,           ///< The next consecutive frame is due at deadline_.
    };

    /// What the frame awaiting confirmation was.
    enum class Pending : uint8_t { Single, First, Consecutive };

    explicit IsoTpSender(const IsoTpConfig& config);

    LinkError expire(uint64_t nowNs);
    void emitConsecutive(IsoTpStep& step, uint64_t nowNs);
    void finish();
    static uint64_t after(uint64_t nowNs, uint64_t intervalNs);

    IsoTpConfig config_;
    bool configured_ = false;
    State state_ = State::Idle;
    Pending pending_ = Pending::Single;
    const uint8_t* message_ = nullptr;
    uint16_t length_ = 0;
    uint16_t offset_ = 0;
    uint8_t sequence_ = 0;
    uint8_t blockSize_ = 0;
    uint8_t blockCount_ = 0;
    uint8_t waits_ = 0;
    bool flowParametersKnown_ = false;
    uint32_t separationNs_ = 0;
    uint64_t deadline_ = kNoDeadline;
};

} // namespace can
