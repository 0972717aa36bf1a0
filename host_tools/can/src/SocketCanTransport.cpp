#include <hostcan/SocketCanTransport.hpp>

#include <cerrno>
#include <cstring>
#include <vector>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

namespace hostcan {

namespace {

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

Received event(BusEventKind kind, std::string detail)
{
    Received r;
    r.kind = Received::Kind::Event;
    r.event = kind;
    r.detail = std::move(detail);
    return r;
}

} // namespace

std::vector<Received> decodeErrorFrame(const LinuxErrorFrame& frame)
{
    std::vector<Received> events;
    const uint32_t id = frame.canId;
    if ((id & CAN_ERR_TX_TIMEOUT) != 0) {
        events.push_back(event(BusEventKind::NoAcknowledge, "transmit time-out"));
    }
    if ((id & CAN_ERR_LOSTARB) != 0) {
        events.push_back(event(BusEventKind::ArbitrationLost, "arbitration lost in bit " +
                                                                  std::to_string(frame.data[0])));
    }
    if ((id & CAN_ERR_CRTL) != 0) {
        const uint8_t status = frame.data[1];
        if ((status & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) != 0) {
            events.push_back(event(BusEventKind::Overrun, "controller buffer overflow"));
        }
        if ((status & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
            events.push_back(event(BusEventKind::ErrorWarning, "error counter at the warning limit"));
        }
        if ((status & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
            events.push_back(event(BusEventKind::ErrorPassive, "error-passive"));
        }
        if ((status & CAN_ERR_CRTL_ACTIVE) != 0) {
            events.push_back(event(BusEventKind::ErrorActive, "back to error-active"));
        }
    }
    if ((id & CAN_ERR_ACK) != 0) {
        events.push_back(event(BusEventKind::NoAcknowledge, "no acknowledge"));
    }
    if ((id & (CAN_ERR_PROT | CAN_ERR_BUSERROR | CAN_ERR_TRX)) != 0) {
        events.push_back(event(BusEventKind::BusError, "bus error (protocol type 0x" +
                                                           std::to_string(frame.data[2]) + ")"));
    }
    if ((id & CAN_ERR_BUSOFF) != 0) {
        events.push_back(event(BusEventKind::BusOff, "bus-off"));
    }
    if ((id & CAN_ERR_RESTARTED) != 0) {
        events.push_back(event(BusEventKind::Restarted, "restarted after bus-off"));
    }
    if ((id & CAN_ERR_CNT) != 0) {
        // Linux 5.x and later report the counters in data bytes 6 and 7.
        for (Received& r : events) {
            r.detail += ", tx errors " + std::to_string(frame.data[6]) + ", rx errors " +
                        std::to_string(frame.data[7]);
        }
    }
    return events;
}

std::unique_ptr<SocketCanTransport> SocketCanTransport::open(const std::string& interface, TransportError& error)
{
    if (interface.empty() || interface.size() >= IFNAMSIZ) {
        error = {TransportError::Kind::BadArgument, "'" + interface + "' is not a network interface name"};
        return nullptr;
    }
    const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        if (errno == EAFNOSUPPORT || errno == EPROTONOSUPPORT) {
            error = {TransportError::Kind::NotAvailable,
                     "this kernel has no SocketCAN (PF_CAN); use the lab VM (docs/guide/lab-vm.md), an slcan "
                     "adapter (-i slcan:/dev/ttyACM0) or the lab bus"};
        } else {
            error = {TransportError::Kind::Open, systemError("cannot open a CAN socket")};
        }
        return nullptr;
    }
    const can_err_mask_t errors = CAN_ERR_MASK;
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errors, sizeof errors) != 0) {
        error = {TransportError::Kind::Open, systemError("cannot ask for error frames")};
        ::close(fd);
        return nullptr;
    }
    const int on = 1;
    (void)::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
    ifreq request{};
    std::strncpy(request.ifr_name, interface.c_str(), IFNAMSIZ - 1);
    if (::ioctl(fd, SIOCGIFINDEX, &request) != 0) {
        error = {TransportError::Kind::Open, systemError("no CAN interface '" + interface + "'")};
        ::close(fd);
        return nullptr;
    }
    sockaddr_can address{};
    address.can_family = AF_CAN;
    address.can_ifindex = request.ifr_ifindex;
    if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
        error = {TransportError::Kind::Open, systemError("cannot bind to '" + interface + "'")};
        ::close(fd);
        return nullptr;
    }
    return std::unique_ptr<SocketCanTransport>(new SocketCanTransport(interface, fd));
}

SocketCanTransport::~SocketCanTransport() { ::close(fd_); }

TransportError SocketCanTransport::send(const can::CanFrame& frame, std::chrono::milliseconds timeout)
{
    can_frame raw{};
    raw.can_id = frame.id() | (frame.isExtended() ? CAN_EFF_FLAG : 0u) | (frame.isRemote() ? CAN_RTR_FLAG : 0u);
    raw.can_dlc = frame.length();
    if (!frame.isRemote()) {
        std::memcpy(raw.data, frame.data(), frame.length());
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
        const ssize_t written = ::write(fd_, &raw, sizeof raw);
        if (written == static_cast<ssize_t>(sizeof raw)) {
            return {};
        }
        if (written < 0 && errno != ENOBUFS && errno != EAGAIN && errno != EINTR) {
            return {errno == ENETDOWN ? TransportError::Kind::Refused : TransportError::Kind::Io,
                    systemError("cannot send on " + interface_)};
        }
        // The interface's queue is full: wait for room, not past the deadline.
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline -
                                                                                std::chrono::steady_clock::now());
        if (left.count() <= 0) {
            return {TransportError::Kind::Refused, interface_ + ": transmit queue full (is anyone acknowledging?)"};
        }
        pollfd p{fd_, POLLOUT, 0};
        (void)::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 10)));
    }
}

Received SocketCanTransport::receive(std::chrono::milliseconds timeout, TransportError& error)
{
    if (!pending_.empty()) {
        Received next = pending_.front();
        pending_.pop_front();
        return next;
    }
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(timeout.count()));
    if (ready < 0) {
        error = {TransportError::Kind::Io, systemError("cannot wait on " + interface_)};
        return {};
    }
    if (ready == 0) {
        return {};
    }
    can_frame raw{};
    iovec vector{&raw, sizeof raw};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
    msghdr message{};
    message.msg_iov = &vector;
    message.msg_iovlen = 1;
    message.msg_control = control;
    message.msg_controllen = sizeof control;
    const ssize_t got = ::recvmsg(fd_, &message, 0);
    if (got < static_cast<ssize_t>(sizeof raw)) {
        error = {TransportError::Kind::Io, systemError("cannot read from " + interface_)};
        return {};
    }
    std::chrono::nanoseconds when{0};
    for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
            timespec stamp{};
            std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
            when = std::chrono::seconds(stamp.tv_sec) + std::chrono::nanoseconds(stamp.tv_nsec);
        }
    }
    if ((raw.can_id & CAN_ERR_FLAG) != 0) {
        LinuxErrorFrame linuxFrame;
        linuxFrame.canId = raw.can_id;
        std::memcpy(linuxFrame.data, raw.data, sizeof linuxFrame.data);
        std::vector<Received> events = decodeErrorFrame(linuxFrame);
        if (events.empty()) {
            events.push_back(event(BusEventKind::BusError, "unclassified error frame"));
        }
        for (Received& e : events) {
            e.timestamp = when;
        }
        pending_.insert(pending_.end(), events.begin() + 1, events.end());
        return events.front();
    }
    const bool extended = (raw.can_id & CAN_EFF_FLAG) != 0;
    const uint32_t id = raw.can_id & (extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    const can::IdFormat format = extended ? can::IdFormat::Extended : can::IdFormat::Standard;
    const can::LinkResult<can::CanFrame> frame = (raw.can_id & CAN_RTR_FLAG) != 0
                                                     ? can::CanFrame::makeRemote(id, format, raw.can_dlc)
                                                     : can::CanFrame::makeData(id, format, raw.data, raw.can_dlc);
    if (!frame.ok()) {
        error = {TransportError::Kind::Protocol, interface_ + ": a frame with data length code " +
                                                      std::to_string(raw.can_dlc) + " was dropped"};
        return {};
    }
    Received r;
    r.kind = Received::Kind::Frame;
    r.frame = frame.value();
    r.timestamp = when;
    return r;
}

} // namespace hostcan
