#include <hostcan/SlcanTransport.hpp>

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <termios.h>
#include <unistd.h>

namespace hostcan {

namespace {

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

// Writes to the adapter. On a socket whose other end has gone, write()
// would raise SIGPIPE and end the whole program; send() with MSG_NOSIGNAL
// reports EPIPE instead, which the caller turns into an error.
ssize_t writeSome(int fd, const char* data, size_t length)
{
    struct stat info{};
    if (::fstat(fd, &info) == 0 && S_ISSOCK(info.st_mode)) {
        return ::send(fd, data, length, MSG_NOSIGNAL);
    }
    return ::write(fd, data, length);
}

can::SlcanMessage simple(can::SlcanMessageKind kind)
{
    can::SlcanMessage message;
    message.kind = kind;
    return message;
}

Received eventFromStatus(uint8_t flags)
{
    Received r;
    r.kind = Received::Kind::Event;
    if ((flags & can::SlcanCodec::kStatusErrorPassive) != 0) {
        r.event = BusEventKind::ErrorPassive;
    } else if ((flags & can::SlcanCodec::kStatusErrorWarning) != 0) {
        r.event = BusEventKind::ErrorWarning;
    } else if ((flags & can::SlcanCodec::kStatusDataOverrun) != 0 ||
               (flags & can::SlcanCodec::kStatusReceiveQueueFull) != 0) {
        r.event = BusEventKind::Overrun;
    } else if ((flags & can::SlcanCodec::kStatusArbitrationLost) != 0) {
        r.event = BusEventKind::ArbitrationLost;
    } else {
        r.event = BusEventKind::BusError;
    }
    char text[32];
    std::snprintf(text, sizeof text, "adapter status flags 0x%02X", flags);
    r.detail = text;
    return r;
}

std::chrono::nanoseconds now()
{
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch());
}

} // namespace

std::unique_ptr<SlcanTransport> SlcanTransport::open(const std::string& path, bool isSocket, uint32_t bitRate,
                                                     TransportError& error)
{
    int fd;
    if (isSocket) {
        sockaddr_un address{};
        address.sun_family = AF_UNIX;
        if (path.size() >= sizeof address.sun_path) {
            error = {TransportError::Kind::BadArgument, "socket path too long: " + path};
            return nullptr;
        }
        std::strncpy(address.sun_path, path.c_str(), sizeof address.sun_path - 1);
        fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
            error = {TransportError::Kind::Open, systemError("cannot connect to " + path)};
            if (fd >= 0) {
                ::close(fd);
            }
            return nullptr;
        }
    } else {
        fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
        if (fd < 0) {
            error = {errno == ENOENT ? TransportError::Kind::NotAvailable : TransportError::Kind::Open,
                     systemError("cannot open " + path)};
            return nullptr;
        }
        termios settings{};
        if (::tcgetattr(fd, &settings) == 0) {
            ::cfmakeraw(&settings);
            ::cfsetispeed(&settings, B115200);
            ::cfsetospeed(&settings, B115200);
            (void)::tcsetattr(fd, TCSANOW, &settings);
        }
    }
    return adopt(fd, (isSocket ? "slcan-socket:" : "slcan:") + path, bitRate, error);
}

std::unique_ptr<SlcanTransport> SlcanTransport::adopt(int fd, std::string name, uint32_t bitRate, TransportError& error)
{
    const can::LinkResult<uint8_t> index = can::SlcanCodec::bitrateIndex(bitRate);
    if (!index.ok()) {
        ::close(fd);
        error = {TransportError::Kind::BadArgument,
                 "slcan adapters have no bit rate " + std::to_string(bitRate) +
                     "; they offer 10000, 20000, 50000, 100000, 125000, 250000, 500000, 800000 and 1000000"};
        return nullptr;
    }
    std::unique_ptr<SlcanTransport> transport(new SlcanTransport(fd, std::move(name), bitRate));
    // An adapter left open by an earlier program refuses S; close it first,
    // whatever it answers, then set the rate and open, which must work.
    (void)transport->command(simple(can::SlcanMessageKind::Close), false);
    can::SlcanMessage rate = simple(can::SlcanMessageKind::SetBitrate);
    rate.bitrateIndex = index.value();
    if (TransportError e = transport->command(rate, true)) {
        error = e;
        return nullptr;
    }
    if (TransportError e = transport->command(simple(can::SlcanMessageKind::Open), true)) {
        error = e;
        return nullptr;
    }
    return transport;
}

SlcanTransport::~SlcanTransport()
{
    // Leave the bus politely; the adapter may already be gone.
    char line[8];
    const can::LinkResult<size_t> n = can::SlcanCodec::format(simple(can::SlcanMessageKind::Close), line, sizeof line);
    if (n.ok()) {
        (void)writeSome(fd_, line, n.value());
    }
    ::close(fd_);
}

TransportError SlcanTransport::writeMessage(const can::SlcanMessage& message)
{
    char line[can::SlcanCodec::kMaxLineLength + 2];
    const can::LinkResult<size_t> n = can::SlcanCodec::format(message, line, sizeof line);
    if (!n.ok()) {
        return {TransportError::Kind::BadArgument, std::string("cannot write that line: ") +
                                                       can::linkErrorName(n.error())};
    }
    size_t done = 0;
    while (done < n.value()) {
        const ssize_t written = writeSome(fd_, line + done, n.value() - done);
        if (written < 0 && errno == EINTR) {
            continue;
        }
        if (written <= 0) {
            return {TransportError::Kind::Io, systemError("cannot write to " + name_)};
        }
        done += static_cast<size_t>(written);
    }
    return {};
}

std::optional<can::SlcanMessage> SlcanTransport::nextMessage(std::chrono::steady_clock::time_point deadline,
                                                             TransportError& error)
{
    for (;;) {
        while (!unread_.empty()) {
            const uint8_t byte = unread_.front();
            unread_.pop_front();
            if (codec_.feed(byte) == can::SlcanCodec::Outcome::Message) {
                return codec_.message();
            }
        }
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() < 0) {
            return std::nullopt;
        }
        pollfd p{fd_, POLLIN, 0};
        const int ready = ::poll(&p, 1, static_cast<int>(left.count()));
        if (ready < 0 && errno != EINTR) {
            error = {TransportError::Kind::Io, systemError("cannot wait on " + name_)};
            return std::nullopt;
        }
        if (ready <= 0) {
            continue;
        }
        uint8_t buffer[256];
        const ssize_t got = ::read(fd_, buffer, sizeof buffer);
        if (got == 0) {
            error = {TransportError::Kind::Closed, name_ + ": the adapter went away"};
            return std::nullopt;
        }
        if (got < 0) {
            if (errno == EINTR || errno == EAGAIN) {
                continue;
            }
            error = {TransportError::Kind::Io, systemError("cannot read from " + name_)};
            return std::nullopt;
        }
        unread_.insert(unread_.end(), buffer, buffer + got);
    }
}

TransportError SlcanTransport::command(const can::SlcanMessage& message, bool mustSucceed)
{
    if (TransportError e = writeMessage(message)) {
        return e;
    }
    const auto deadline = std::chrono::steady_clock::now() + kReplyTimeout;
    for (;;) {
        TransportError error;
        const std::optional<can::SlcanMessage> reply = nextMessage(deadline, error);
        if (error) {
            return error;
        }
        if (!reply) {
            return mustSucceed ? TransportError{TransportError::Kind::Protocol,
                                                name_ + ": the adapter did not answer within " +
                                                    std::to_string(kReplyTimeout.count()) + " ms"}
                               : TransportError{};
        }
        if (reply->kind == can::SlcanMessageKind::Ok) {
            return {};
        }
        if (reply->kind == can::SlcanMessageKind::Error) {
            return mustSucceed ? TransportError{TransportError::Kind::Refused, name_ + ": the adapter refused the command"}
                               : TransportError{};
        }
        if (reply->kind == can::SlcanMessageKind::Frame) {
            // Traffic that came before the reply is kept for receive().
            Received r;
            r.kind = Received::Kind::Frame;
            r.frame = reply->frame;
            r.timestamp = now();
            pending_.push_back(r);
        }
    }
}

TransportError SlcanTransport::send(const can::CanFrame& frame, std::chrono::milliseconds)
{
    can::SlcanMessage message;
    message.kind = can::SlcanMessageKind::Frame;
    message.frame = frame;
    return writeMessage(message);
}

Received SlcanTransport::receive(std::chrono::milliseconds timeout, TransportError& error)
{
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
        if (!pending_.empty()) {
            Received next = pending_.front();
            pending_.pop_front();
            return next;
        }
        const std::optional<can::SlcanMessage> message = nextMessage(deadline, error);
        if (!message) {
            return {};
        }
        switch (message->kind) {
        case can::SlcanMessageKind::Frame: {
            Received r;
            r.kind = Received::Kind::Frame;
            r.frame = message->frame;
            r.timestamp = now();
            return r;
        }
        case can::SlcanMessageKind::StatusFlags:
            if (message->statusFlags != 0) {
                Received r = eventFromStatus(message->statusFlags);
                r.timestamp = now();
                return r;
            }
            break;
        default:
            break; // Acknowledgements of our own frames ('z', 'Z', CR) carry nothing to report.
        }
    }
}

} // namespace hostcan
