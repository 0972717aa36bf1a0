#include <hostflash/SerialFlashLink.hpp>

#include <fmt/core.h>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <termios.h>
#include <unistd.h>

namespace hostflash {

namespace {

bool writeAll(int descriptor, const uint8_t* data, size_t length)
{
    while (length > 0) {
        const ssize_t written = ::write(descriptor, data, length);
        if (written < 0 && errno == EINTR) {
            continue;
        }
        if (written <= 0) {
            return false;
        }
        data += written;
        length -= static_cast<size_t>(written);
    }
    return true;
}

} // namespace

std::unique_ptr<SerialFlashLink> SerialFlashLink::open(const std::string& device, LinkError& error, std::string& why)
{
    if (device.empty()) {
        error = LinkError::BadArgument;
        why = "no device given";
        return nullptr;
    }
    if (device.rfind("unix:", 0) == 0) {
        const std::string path = device.substr(5);
        sockaddr_un address{};
        if (path.empty() || path.size() >= sizeof address.sun_path) {
            error = LinkError::BadArgument;
            why = fmt::format("'{}' is no Unix socket path", path);
            return nullptr;
        }
        const int descriptor = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        address.sun_family = AF_UNIX;
        std::memcpy(address.sun_path, path.c_str(), path.size());
        if (descriptor < 0 || ::connect(descriptor, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
            error = LinkError::NotAvailable;
            why = fmt::format("cannot connect to {}: {}", path, std::strerror(errno));
            if (descriptor >= 0) {
                ::close(descriptor);
            }
            return nullptr;
        }
        return std::unique_ptr<SerialFlashLink>(new SerialFlashLink(descriptor));
    }
    const int descriptor = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (descriptor < 0) {
        error = errno == ENOENT ? LinkError::NotAvailable : LinkError::Failed;
        why = fmt::format("cannot open {}: {}", device, std::strerror(errno));
        return nullptr;
    }
    termios settings{};
    if (::tcgetattr(descriptor, &settings) == 0) {
        ::cfmakeraw(&settings);
        ::cfsetispeed(&settings, B115200);
        ::cfsetospeed(&settings, B115200);
        settings.c_cflag |= CLOCAL | CREAD;
        settings.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS);
        ::tcsetattr(descriptor, TCSANOW, &settings);
        ::tcflush(descriptor, TCIOFLUSH);
    }
    return std::unique_ptr<SerialFlashLink>(new SerialFlashLink(descriptor));
}

SerialFlashLink::~SerialFlashLink() { ::close(descriptor_); }

LinkError SerialFlashLink::exchange(const flash::FlashMessage& request, flash::FlashMessage& reply,
                              std::chrono::milliseconds timeout, std::string& why)
{
    uint8_t payload[flash::kMaxMessage];
    const size_t length = request.encode(payload, sizeof payload);
    uint8_t framed[flash::kMaxMessage + flash::SerialFramer::kOverhead];
    const size_t frameLength = flash::SerialFramer::frame(payload, length, framed, sizeof framed);
    if (length == 0 || frameLength == 0) {
        why = "the request does not encode";
        return LinkError::BadArgument;
    }
    if (!writeAll(descriptor_, framed, frameLength)) {
        why = fmt::format("cannot send: {}", std::strerror(errno));
        return LinkError::Failed;
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) {
            why = "no reply";
            return LinkError::Timeout;
        }
        pollfd ready{descriptor_, POLLIN, 0};
        const int polled = ::poll(&ready, 1, static_cast<int>(left.count()));
        if (polled < 0 && errno == EINTR) {
            continue;
        }
        if (polled <= 0) {
            continue;
        }
        uint8_t bytes[512];
        const ssize_t count = ::read(descriptor_, bytes, sizeof bytes);
        if (count <= 0) {
            why = count == 0 ? "the node's line closed" : fmt::format("cannot read: {}", std::strerror(errno));
            return LinkError::Failed;
        }
        for (ssize_t i = 0; i < count; ++i) {
            if (!receiver_.receive(bytes[i])) {
                continue;
            }
            flash::FlashMessage decoded;
            if (flash::FlashMessage::decode(receiver_.payload(), receiver_.payloadLength(), decoded) &&
                decoded.tag == request.tag) {
                reply = decoded;
                return LinkError::None;
            }
        }
    }
}

} // namespace hostflash
