// The parameters of one ISO-TP connection, shared by its sender and receiver.
//
// The connection is a pair of CAN identifiers, as in a Linux can-isotp
// socket: this end sends data and flow control on txId and listens on rxId.
// For a DCOS transfer from node A to node B at priority p, A's txId is
// MessageIdentifier(p, Segmented, B, A) and its rxId the reversed one.
//
// The defaults interoperate with Linux's can-isotp sockets as isotpsend and
// isotprecv open them without options: no padding, block size 0 (the whole
// message without further flow control), STmin 0, and 1 s time-outs.
#pragma once

#include <can/CanFrame.hpp>
#include <can/IsoTpPci.hpp>
#include <can/LinkError.hpp>

#include <stdint.h>

namespace can {

struct IsoTpConfig {
    /// ISO 15765-2 "Network layer timing parameter values": the time-out
    /// values of N_As, N_Ar, N_Bs and N_Cr are 1000 ms (also Linux's
    /// ISOTP_FC_TIMEOUT).
    static constexpr uint64_t kDefaultTimeoutNs = 1000000000;
    /// How many flow control Wait frames in a row the sender accepts before
    /// it gives up with WaitLimitExceeded. ISO 15765-2 bounds the receiver's
    /// waits by N_WFTmax but leaves the sender none; a control node must not
    /// let a peer hold a transfer forever, so the default bounds a stall to
    /// about 16 x N_Bs. Linux's receiver never sends Wait frames.
    static constexpr uint8_t kDefaultMaxWaitFrames = 16;

    uint32_t txId = 0;                    ///< Identifier this end sends on.
    uint32_t rxId = 0;                    ///< Identifier this end receives on.
    IdFormat format = IdFormat::Extended; ///< Format of both identifiers.

    IsoTpPadding padding;             ///< How short frames are sent.
    bool requirePaddedFrames = false; ///< Ignore received frames shorter than 8 bytes (ShortFrame).

    /// BlockSize this receiver announces: consecutive frames between flow
    /// controls, 0 for no limit ("BlockSize (BS) parameter definition").
    uint8_t blockSize = 0;
    /// Separation time this receiver asks for between consecutive frames;
    /// rounded up to what STmin expresses, at most 127 ms.
    uint32_t separationTimeNs = 0;

    uint64_t timeoutAsNs = kDefaultTimeoutNs; ///< N_As: a sent frame confirmed by the controller.
    uint64_t timeoutBsNs = kDefaultTimeoutNs; ///< N_Bs: first frame or block sent -> flow control.
    uint64_t timeoutCrNs = kDefaultTimeoutNs; ///< N_Cr: flow control or frame -> next consecutive frame.

    uint8_t maxWaitFrames = kDefaultMaxWaitFrames; ///< Wait frames accepted in a row; 0 accepts none.

    /// Ok, or InvalidConfiguration (or InvalidIdentifier for an identifier
    /// that does not fit its format) naming the first value out of range.
    LinkError validate() const;
};

} // namespace can
