// ISO 15765-2 transfers through the Linux kernel's own ISO-TP sockets
// (CAN_ISOTP, the can-isotp module) on a SocketCAN interface: the kernel
// segments and reassembles, so the tool can stand in for can-utils'
// isotpsend and isotprecv, and a transfer between this and the link
// layer's own state machines (IsoTpEndpoint) is one between two
// implementations, only one of them ours.
#pragma once

#include <hostcan/IsoTpEndpoint.hpp>

#include <chrono>
#include <string>
#include <vector>

namespace hostcan {

/// Sends @p message (1 to 4095 bytes) on @p config's connection of the
/// SocketCAN interface @p interface and waits, at most @p timeout, until the
/// kernel has sent it all (CAN_ISOTP_WAIT_TX_DONE). A transfer the kernel
/// gave up (no flow control within N_Bs) is TimeoutBs; a socket that cannot
/// be had is a TransportError (NotAvailable where the kernel has no CAN).
IsoTpOutcome kernelIsoTpSend(const std::string& interface, const can::IsoTpConfig& config,
                             const std::vector<uint8_t>& message, std::chrono::milliseconds timeout);

/// Receives one message on @p config's connection, waiting at most
/// @p firstFrameTimeout for the kernel to hand over a whole one; TimeoutCr
/// when none comes.
IsoTpOutcome kernelIsoTpReceive(const std::string& interface, const can::IsoTpConfig& config,
                                std::chrono::milliseconds firstFrameTimeout);

} // namespace hostcan
