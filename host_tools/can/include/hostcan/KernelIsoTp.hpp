// ISO 15765-2 transfers through the Linux kernel's own ISO-TP sockets
// (CAN_ISOTP, the can-isotp module) on a SocketCAN interface: the kernel
// segments and reassembles, so the tool can stand in for can-utils'
// isotpsend and isotprecv, and a transfer between this and the link
// layer's own state machines (IsoTpEndpoint) is one between two
// implementations, only one of them ours.
#pragma once

#include <hostcan/IsoTpEndpoint.hpp>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

namespace hostcan {

/// One connection's kernel socket, kept open across messages: a request
/// sent on it and its reply received on it, so that a reply which follows
/// at once is not lost (a can-isotp socket sees only the frames that
/// arrive after it was bound).
class KernelIsoTpSocket {
public:
    /// The socket for @p config's connection on SocketCAN interface
    /// @p interface, or null with @p error (NotAvailable where the kernel has no CAN).
    static std::unique_ptr<KernelIsoTpSocket> open(const std::string& interface, const can::IsoTpConfig& config,
                                                   TransportError& error);
    ~KernelIsoTpSocket();
    KernelIsoTpSocket(const KernelIsoTpSocket&) = delete;
    KernelIsoTpSocket& operator=(const KernelIsoTpSocket&) = delete;

    /// Sends @p message (1 to 4095 bytes), waiting at most @p timeout until
    /// the kernel has sent it all; a transfer it gave up is TimeoutBs.
    IsoTpOutcome send(const std::vector<uint8_t>& message, std::chrono::milliseconds timeout);
    /// Receives one message, waiting at most @p firstFrameTimeout; TimeoutCr when none comes.
    IsoTpOutcome receive(std::chrono::milliseconds firstFrameTimeout);

private:
    explicit KernelIsoTpSocket(int fd) : fd_(fd) {}
    int fd_;
};

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
