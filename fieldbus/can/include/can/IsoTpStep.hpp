// What one input did to an ISO-TP state machine (IsoTpSender, IsoTpReceiver).
//
// The state machines own no timer and no controller: the caller feeds them
// frames, transmit confirmations and the time, and each call answers with a
// step saying what to put on the bus and what happened. One input can do
// several things at once: a first frame that arrives in the middle of a
// reception ends the old message (aborted) and answers the new one with a
// flow control (transmit), so the fields are independent, not alternatives.
#pragma once

#include <can/CanFrame.hpp>
#include <can/LinkError.hpp>

#include <stdint.h>

namespace can {

struct IsoTpStep {
    /// Hand `frame` to the controller now; the sender then waits for its confirmation.
    bool transmit = false;
    CanFrame frame;
    /// The message is done: all of it sent and confirmed (sender), or all of
    /// it in the caller's buffer, `length` bytes (receiver).
    bool completed = false;
    uint16_t length = 0;
    /// A transfer in progress ended without its message, and why (ISO 15765-2
    /// N_Result); Ok when none ended.
    LinkError aborted = LinkError::Ok;
    /// Why this input was refused; Ok when it was taken. A frame the standard
    /// says to ignore changes nothing; a message too long for the receiver's
    /// buffer (BufferOverflow) comes with the Overflow flow control to send.
    LinkError rejected = LinkError::Ok;
};

} // namespace can
