// ISO 15765-2 transfers over any transport, with the link layer's own state
// machines (can::IsoTpSender, can::IsoTpReceiver) driven by the host's
// monotonic clock: the same code a DCOS node runs, so a transfer between
// this endpoint and Linux's kernel ISO-TP sockets (can-utils' isotpsend and
// isotprecv) proves the firmware's segmentation against an implementation
// we did not write.
//
// A frame the transport accepted counts as confirmed at once: SocketCAN and
// slcan report nothing later, and a frame the bus never takes shows up as
// the peer's missing flow control (N_Bs) or the receiver's N_Cr.
#pragma once

#include <hostcan/Transport.hpp>

#include <can/IsoTpConfig.hpp>
#include <can/LinkError.hpp>

#include <vector>

namespace hostcan {

struct IsoTpOutcome {
    can::LinkError error = can::LinkError::Ok; ///< Ok, or the ISO 15765-2 N_Result that ended the transfer.
    TransportError transport;                  ///< Set when the transport itself failed.
    std::vector<uint8_t> message;              ///< What was received (receive only).
};

/// Sends @p message (1 to 4095 bytes) on @p config's connection.
IsoTpOutcome isoTpSend(Transport& transport, const can::IsoTpConfig& config, const std::vector<uint8_t>& message);

/// Receives one message on @p config's connection, waiting at most
/// @p firstFrameTimeout for it to begin; Timeout-like TimeoutCr when it does not.
IsoTpOutcome isoTpReceive(Transport& transport, const can::IsoTpConfig& config,
                          std::chrono::milliseconds firstFrameTimeout);

} // namespace hostcan
