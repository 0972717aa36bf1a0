#include <hostcan/KernelIsoTp.hpp>

#include <linux/can.h>
#include <linux/can/isotp.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace hostcan {
namespace {

// The padding byte can-utils' isotpsend -p and our own endpoint use.
constexpr uint8_t kPaddingByte = 0xCC;
// The largest ISO 15765-2 message of classic CAN (a 12-bit length).
constexpr size_t kMaxMessage = 4095;

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

// A socket bound to the connection, or -1 with @p error set.
int openSocket(const std::string& interface, const can::IsoTpConfig& config, bool waitTxDone, TransportError& error)
{
    if (interface.empty() || interface.size() >= IFNAMSIZ) {
        error = {TransportError::Kind::BadArgument, "'" + interface + "' is not a network interface name"};
        return -1;
    }
    const int fd = ::socket(PF_CAN, SOCK_DGRAM | SOCK_CLOEXEC, CAN_ISOTP);
    if (fd < 0) {
        if (errno == EAFNOSUPPORT || errno == EPROTONOSUPPORT) {
            error = {TransportError::Kind::NotAvailable,
                     "this kernel has no ISO-TP sockets (PF_CAN with can-isotp); use the lab VM "
                     "(docs/guide/lab-vm.md) or the tool's own ISO-TP (without --kernel)"};
        } else {
            error = {TransportError::Kind::Open, systemError("cannot open an ISO-TP socket")};
        }
        return -1;
    }
    can_isotp_options options{};
    if (config.padding.enabled) {
        // Both ways, as isotpsend -p and isotprecv -p pad: our frames, and
        // what we accept from the other end is not checked for it.
        options.flags |= CAN_ISOTP_TX_PADDING;
        options.txpad_content = kPaddingByte;
    }
    if (waitTxDone) {
        // The write returns when the last frame has gone, or with the
        // transfer's error, so the exit status says whether it arrived.
        options.flags |= CAN_ISOTP_WAIT_TX_DONE;
    }
    if (::setsockopt(fd, SOL_CAN_ISOTP, CAN_ISOTP_OPTS, &options, sizeof options) != 0) {
        error = {TransportError::Kind::Open, systemError("cannot set the ISO-TP options")};
        ::close(fd);
        return -1;
    }
    const unsigned index = ::if_nametoindex(interface.c_str());
    if (index == 0) {
        error = {TransportError::Kind::Open, systemError("no CAN interface '" + interface + "'")};
        ::close(fd);
        return -1;
    }
    const canid_t flag = config.format == can::IdFormat::Extended ? CAN_EFF_FLAG : 0u;
    sockaddr_can address{};
    address.can_family = AF_CAN;
    address.can_ifindex = static_cast<int>(index);
    address.can_addr.tp.tx_id = config.txId | flag;
    address.can_addr.tp.rx_id = config.rxId | flag;
    if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
        error = {TransportError::Kind::Open, systemError("cannot bind an ISO-TP socket to '" + interface + "'")};
        ::close(fd);
        return -1;
    }
    return fd;
}

} // namespace

std::unique_ptr<KernelIsoTpSocket> KernelIsoTpSocket::open(const std::string& interface,
                                                           const can::IsoTpConfig& config, TransportError& error)
{
    const int fd = openSocket(interface, config, true, error);
    return fd < 0 ? nullptr : std::unique_ptr<KernelIsoTpSocket>(new KernelIsoTpSocket(fd));
}

KernelIsoTpSocket::~KernelIsoTpSocket() { ::close(fd_); }

IsoTpOutcome KernelIsoTpSocket::send(const std::vector<uint8_t>& message, std::chrono::milliseconds timeout)
{
    IsoTpOutcome outcome;
    if (message.empty() || message.size() > kMaxMessage) {
        outcome.transport = {TransportError::Kind::BadArgument, "an ISO-TP message is 1 to 4095 bytes"};
        return outcome;
    }
    // A bound on the whole write: the kernel's own N_Bs ends a transfer
    // without flow control, this ends one whose flow control says wait for ever.
    timeval limit{};
    limit.tv_sec = static_cast<time_t>(timeout.count() / 1000);
    limit.tv_usec = static_cast<suseconds_t>((timeout.count() % 1000) * 1000);
    (void)::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof limit);
    const ssize_t written = ::write(fd_, message.data(), message.size());
    if (written != static_cast<ssize_t>(message.size())) {
        if (written < 0 && (errno == ECOMM || errno == EAGAIN || errno == EWOULDBLOCK)) {
            // The kernel reports a transfer it gave up (N_Bs, a flow
            // control it refused) as ECOMM.
            outcome.error = can::LinkError::TimeoutBs;
        } else {
            outcome.transport = {TransportError::Kind::Io, systemError("the kernel did not send the message")};
        }
    }
    return outcome;
}

IsoTpOutcome KernelIsoTpSocket::receive(std::chrono::milliseconds firstFrameTimeout)
{
    IsoTpOutcome outcome;
    pollfd ready{fd_, POLLIN, 0};
    const int polled = ::poll(&ready, 1, static_cast<int>(firstFrameTimeout.count()));
    if (polled == 0) {
        outcome.error = can::LinkError::TimeoutCr;
    } else if (polled < 0) {
        outcome.transport = {TransportError::Kind::Io, systemError("waiting for the ISO-TP message failed")};
    } else {
        std::vector<uint8_t> buffer(kMaxMessage + 1);
        const ssize_t got = ::read(fd_, buffer.data(), buffer.size());
        if (got > 0) {
            buffer.resize(static_cast<size_t>(got));
            outcome.message = std::move(buffer);
        } else if (got < 0 && errno == ECOMM) {
            // A transfer that began and broke off (N_Cr, a wrong sequence number).
            outcome.error = can::LinkError::TimeoutCr;
        } else {
            outcome.transport = {TransportError::Kind::Io, systemError("reading the ISO-TP message failed")};
        }
    }
    return outcome;
}

IsoTpOutcome kernelIsoTpSend(const std::string& interface, const can::IsoTpConfig& config,
                             const std::vector<uint8_t>& message, std::chrono::milliseconds timeout)
{
    IsoTpOutcome outcome;
    const std::unique_ptr<KernelIsoTpSocket> socket = KernelIsoTpSocket::open(interface, config, outcome.transport);
    return socket ? socket->send(message, timeout) : outcome;
}

IsoTpOutcome kernelIsoTpReceive(const std::string& interface, const can::IsoTpConfig& config,
                                std::chrono::milliseconds firstFrameTimeout)
{
    IsoTpOutcome outcome;
    const std::unique_ptr<KernelIsoTpSocket> socket = KernelIsoTpSocket::open(interface, config, outcome.transport);
    return socket ? socket->receive(firstFrameTimeout) : outcome;
}

} // namespace hostcan
