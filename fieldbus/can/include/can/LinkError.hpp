// Why the CAN link layer refused a frame, a line or a request.
//
// The kernel's dcos::Status says what kind of failure a service met, which is
// what a task needs to decide what to do next. The link layer must say more:
// ISO 15765-2 requires a receiver to report *which* rule a peer broke
// (N_Result: N_TIMEOUT_A, N_WRONG_SN, N_INVALID_FS, ...), and an engineer
// chasing a bad adapter or a noisy bus needs to know whether a line had a
// bad hex digit or a bad length. So the link layer reports a LinkError, and
// toStatus() folds it into the kernel's Status where a service of the
// network interfaces manager (seed 7.13) hands the result to a task.
//
// Errors are values, never exceptions: the same code runs in the freestanding
// firmware, built with -fno-exceptions. The numeric values are stable so that
// counters and logs keep their meaning; new reasons take new values.
#pragma once

#include <dcos/Status.hpp>

#include <stdint.h>

namespace can {

enum class LinkError : uint8_t {
    Ok = 0,

    // A CAN frame (CanFrame).
    InvalidIdentifier = 1,  ///< The identifier does not fit 11 bits (standard) or 29 bits (extended).
    InvalidDataLength = 2,  ///< The data length code is above 8 (classic CAN).

    // A DCOS identifier (MessageIdentifier).
    NotExtendedFrame = 3,       ///< A standard (11-bit) frame: DCOS frames are always extended.
    UnexpectedRemoteFrame = 4,  ///< A remote frame where only data frames are used.
    InvalidPriority = 5,        ///< A task priority above the lowest, 31.
    InvalidNodeNumber = 6,      ///< The broadcast number used as a source node.
    UnassignedMessageType = 7,  ///< A message type no DCOS layer has been given.

    // ISO 15765-2 N_Result values reported at the end of a transfer.
    TimeoutA = 8,              ///< N_TIMEOUT_A: a frame was not confirmed sent within N_As.
    TimeoutBs = 9,             ///< N_TIMEOUT_Bs: no flow control arrived within N_Bs.
    TimeoutCr = 10,            ///< N_TIMEOUT_Cr: no consecutive frame arrived within N_Cr.
    WrongSequenceNumber = 11,  ///< N_WRONG_SN: a consecutive frame was duplicated, lost or out of order.
    InvalidFlowStatus = 12,    ///< N_INVALID_FS: a flow control frame with a reserved or misplaced status.
    UnexpectedPdu = 13,        ///< N_UNEXP_PDU: a new message began while one was being received.
    WaitLimitExceeded = 14,    ///< N_WFT_OVRN: the receiver asked to wait more often than allowed.
    BufferOverflow = 15,       ///< N_BUFFER_OVFLW: the message is longer than the buffer for it.

    // ISO-TP frames the standard says to ignore, and misuse of the state machines.
    ReservedPciType = 16,           ///< N_PCItype 4..15, reserved by ISO 15765-2.
    InvalidSingleFrameLength = 17,  ///< SF_DL of 0, above 7, or beyond the frame's data.
    InvalidFirstFrame = 18,         ///< A first frame that is not 8 bytes long or announces too few bytes.
    ShortFrame = 19,                ///< A frame with fewer bytes than its N_PCI and data need.
    NotExpected = 20,               ///< A frame or confirmation the state machine was not waiting for.
    WrongIdentifier = 21,           ///< A frame on another identifier than the transfer's.
    InvalidMessageLength = 22,      ///< A message of 0 bytes or above 4095 bytes to send.
    Busy = 23,                      ///< A transfer is already in progress.
    InvalidConfiguration = 24,      ///< A configuration value is out of its documented range.

    // The slcan (Lawicel) line protocol.
    InvalidHexDigit = 25,    ///< A character that should be a hexadecimal digit is not.
    LineTooLong = 26,        ///< A line longer than any the protocol defines.
    InvalidLineLength = 27,  ///< A line whose length does not match its command.
    UnknownCommand = 28,     ///< A line starting with a command letter this codec does not implement.
    InvalidArgument = 29,    ///< An argument out of range: a missing buffer, an slcan argument (S9, Z2, ...).
    LineInterrupted = 30,    ///< A BELL arrived in the middle of a line.
    BufferTooSmall = 31,     ///< The output buffer cannot hold the formatted line.
};

/// A short, stable English name for @p error, for logs and the console.
const char* linkErrorName(LinkError error);

/// The kernel status a service reports for @p error.
///
/// Malformed input and refused configuration become InvalidArgument, the
/// three ISO-TP time-outs Timeout, a message too long for its buffer
/// NoMemory, a transfer already running Busy, and a command this codec does
/// not implement NotSupported; every other protocol violation by the peer is
/// InvalidArgument as well, since it is the peer's input that was wrong.
dcos::Status toStatus(LinkError error);

} // namespace can
