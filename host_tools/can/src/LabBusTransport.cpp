#include <hostcan/LabBusTransport.hpp>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <sstream>
#include <vector>

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace hostcan {

namespace {

constexpr int kProtocolVersion = 1;
// A hub line is at most 256 bytes (docs/protocols/labbus.md, "Messages");
// anything longer is not the hub speaking.
constexpr size_t kMaxLine = 256;

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

std::vector<std::string> words(const std::string& line)
{
    std::vector<std::string> out;
    std::istringstream stream(line);
    std::string word;
    while (stream >> word) {
        out.push_back(word);
    }
    return out;
}

template <class T>
bool number(const std::string& text, T& value, int base = 10)
{
    const auto [end, problem] = std::from_chars(text.data(), text.data() + text.size(), value, base);
    return problem == std::errc() && end == text.data() + text.size();
}

} // namespace

std::string LabBusTransport::frameWords(const can::CanFrame& frame)
{
    static const char digits[] = "0123456789abcdef";
    char id[16];
    std::snprintf(id, sizeof id, "%x", static_cast<unsigned>(frame.id()));
    std::string text = std::string(id) + (frame.isExtended() ? " X" : " S") + (frame.isRemote() ? "R " : "D ") +
                       std::to_string(frame.length()) + " ";
    if (frame.isRemote() || frame.length() == 0) {
        return text + "-";
    }
    for (uint8_t i = 0; i < frame.length(); ++i) {
        text += digits[frame.byte(i) >> 4];
        text += digits[frame.byte(i) & 0xF];
    }
    return text;
}

std::unique_ptr<LabBusTransport> LabBusTransport::open(const std::string& socketPath, const std::string& bus,
                                                       TransportError& error)
{
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    if (socketPath.empty() || socketPath.size() >= sizeof address.sun_path || bus.empty() ||
        bus.find_first_of(" \n") != std::string::npos) {
        error = {TransportError::Kind::BadArgument, "write lab:<hub socket>:<bus>, e.g. lab:/tmp/lab.sock:can0"};
        return nullptr;
    }
    std::strncpy(address.sun_path, socketPath.c_str(), sizeof address.sun_path - 1);
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
        error = {errno == ENOENT ? TransportError::Kind::NotAvailable : TransportError::Kind::Open,
                 systemError("no lab bus hub at " + socketPath)};
        if (fd >= 0) {
            ::close(fd);
        }
        return nullptr;
    }
    std::unique_ptr<LabBusTransport> transport(new LabBusTransport(fd, bus));
    const auto deadline = std::chrono::steady_clock::now() + kReplyTimeout;
    // The hub names ports after the participant, which must be one word
    // without dots and unique: the tool's process id makes it so.
    const std::string name = "dcoscan" + std::to_string(::getpid());
    if (TransportError e = transport->writeLine("HELLO " + std::to_string(kProtocolVersion) + " " + name + " host")) {
        error = e;
        return nullptr;
    }
    std::optional<std::string> welcome = transport->readLine(deadline, error);
    if (!welcome || words(*welcome).empty() || words(*welcome)[0] != "WELCOME") {
        if (!error) {
            error = {TransportError::Kind::Protocol,
                     "the hub did not welcome us: " + (welcome ? *welcome : std::string("no answer"))};
        }
        return nullptr;
    }
    if (TransportError e = transport->writeLine("ATTACH 0 " + bus)) {
        error = e;
        return nullptr;
    }
    for (;;) {
        std::optional<std::string> answer = transport->readLine(deadline, error);
        if (!answer) {
            if (!error) {
                error = {TransportError::Kind::Protocol, "the hub did not answer ATTACH"};
            }
            return nullptr;
        }
        const std::vector<std::string> w = words(*answer);
        if (!w.empty() && w[0] == "REFUSED") {
            error = {TransportError::Kind::Open, "the hub refused bus '" + bus + "': " + *answer};
            return nullptr;
        }
        if (w.size() >= 4 && w[0] == "ATTACHED" && number(w[3], transport->bitNs_) && transport->bitNs_ > 0) {
            return transport;
        }
    }
}

LabBusTransport::~LabBusTransport()
{
    (void)writeLine("BYE");
    ::close(fd_);
}

std::optional<uint32_t> LabBusTransport::bitRate() const
{
    return bitNs_ == 0 ? std::nullopt : std::optional<uint32_t>(static_cast<uint32_t>(1'000'000'000u / bitNs_));
}

TransportError LabBusTransport::writeLine(const std::string& line)
{
    const std::string text = line + "\n";
    size_t done = 0;
    while (done < text.size()) {
        const ssize_t sent = ::send(fd_, text.data() + done, text.size() - done, MSG_NOSIGNAL);
        if (sent < 0 && errno == EINTR) {
            continue;
        }
        if (sent <= 0) {
            return {TransportError::Kind::Closed, systemError("the lab bus hub went away")};
        }
        done += static_cast<size_t>(sent);
    }
    return {};
}

std::optional<std::string> LabBusTransport::readLine(std::chrono::steady_clock::time_point deadline,
                                                     TransportError& error)
{
    for (;;) {
        const size_t end = unread_.find('\n');
        if (end != std::string::npos) {
            std::string line = unread_.substr(0, end);
            unread_.erase(0, end + 1);
            return line;
        }
        if (unread_.size() > kMaxLine) {
            error = {TransportError::Kind::Protocol, "the hub sent a line longer than the protocol allows"};
            return std::nullopt;
        }
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() < 0) {
            return std::nullopt;
        }
        pollfd p{fd_, POLLIN, 0};
        const int ready = ::poll(&p, 1, static_cast<int>(left.count()));
        if (ready < 0 && errno != EINTR) {
            error = {TransportError::Kind::Io, systemError("cannot wait on the lab bus hub")};
            return std::nullopt;
        }
        if (ready <= 0) {
            continue;
        }
        char buffer[4096];
        const ssize_t got = ::recv(fd_, buffer, sizeof buffer, 0);
        if (got == 0) {
            error = {TransportError::Kind::Closed, "the lab bus hub closed the connection"};
            return std::nullopt;
        }
        if (got < 0) {
            if (errno == EINTR) {
                continue;
            }
            error = {TransportError::Kind::Io, systemError("cannot read from the lab bus hub")};
            return std::nullopt;
        }
        unread_.append(buffer, static_cast<size_t>(got));
    }
}

TransportError LabBusTransport::send(const can::CanFrame& frame, std::chrono::milliseconds timeout)
{
    if (TransportError e = writeLine("TX 0 - " + frameWords(frame) + " -")) {
        return e;
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
        TransportError error;
        const std::optional<std::string> line = readLine(deadline, error);
        if (error) {
            return error;
        }
        if (!line) {
            return {TransportError::Kind::Refused,
                    "the frame was not on the lab bus within " + std::to_string(timeout.count()) +
                        " ms (is another node there to acknowledge it?)"};
        }
        const std::vector<std::string> w = words(*line);
        if (!w.empty() && w[0] == "TXOK") {
            return {};
        }
        if (!w.empty() && w[0] == "ABORTED") {
            return {TransportError::Kind::Refused, "the hub aborted the frame"};
        }
        std::optional<Received> event = parseEvent(*line, error);
        if (error) {
            return error;
        }
        if (!event) {
            continue;
        }
        const bool final = w.size() >= 7 && w[0] == "ERR" && w[4] == "tx" && w[6].find("final") != std::string::npos;
        if (final || (w[0] == "LOST" && w.size() >= 6 && w[5] == "1")) {
            return {TransportError::Kind::Refused, "the frame was given up: " + event->detail};
        }
        pending_.push_back(*event); // Traffic of others, for receive().
    }
}

std::optional<Received> LabBusTransport::parseEvent(const std::string& line, TransportError& error)
{
    const std::vector<std::string> w = words(line);
    if (w.empty()) {
        return std::nullopt;
    }
    if (w[0] == "ERROR") {
        error = {TransportError::Kind::Protocol, "the hub reports: " + line};
        return std::nullopt;
    }
    // Events: <EVENT> <port> <epoch> <time> [arguments].
    uint64_t when = 0;
    if (w.size() < 4 || !number(w[3], when)) {
        return std::nullopt; // DONE, NAK and other answers carry nothing to report.
    }
    Received r;
    r.timestamp = std::chrono::nanoseconds(when);
    r.emulatedTime = true;
    if (w[0] == "RX" && w.size() >= 8) {
        uint32_t id = 0;
        unsigned dlc = 0;
        const std::string& format = w[5];
        if (!number(w[4], id, 16) || !number(w[6], dlc) || dlc > 15 || format.size() != 2 ||
            (format[0] != 'S' && format[0] != 'X') || (format[1] != 'D' && format[1] != 'R')) {
            error = {TransportError::Kind::Protocol, "the hub sent a frame this tool cannot read: " + line};
            return std::nullopt;
        }
        const can::IdFormat idFormat = format[0] == 'X' ? can::IdFormat::Extended : can::IdFormat::Standard;
        if (dlc > can::CanFrame::kMaxDataLength) {
            // A DLC of 9-15 is legal on the bus; the link layer refuses it, as SocketCAN does.
            r.kind = Received::Kind::Event;
            r.event = BusEventKind::BusError;
            r.detail = "a frame with data length code " + std::to_string(dlc) + " was dropped";
            return r;
        }
        uint8_t data[8] = {};
        if (format[1] == 'D' && dlc > 0) {
            const std::string& hex = w[7];
            if (hex.size() != 2 * dlc) {
                error = {TransportError::Kind::Protocol, "the hub sent a frame with the wrong data: " + line};
                return std::nullopt;
            }
            for (unsigned i = 0; i < dlc; ++i) {
                if (!number(hex.substr(2 * i, 2), data[i], 16)) {
                    error = {TransportError::Kind::Protocol, "the hub sent bad data: " + line};
                    return std::nullopt;
                }
            }
        }
        const can::LinkResult<can::CanFrame> frame = format[1] == 'R'
                                                         ? can::CanFrame::makeRemote(id, idFormat, static_cast<uint8_t>(dlc))
                                                         : can::CanFrame::makeData(id, idFormat, data, static_cast<uint8_t>(dlc));
        if (!frame.ok()) {
            error = {TransportError::Kind::Protocol, "the hub sent an impossible frame: " + line};
            return std::nullopt;
        }
        r.kind = Received::Kind::Frame;
        r.frame = frame.value();
        return r;
    }
    r.kind = Received::Kind::Event;
    if (w[0] == "ERR" && w.size() >= 7 && w[4] == "tx") {
        r.event = w[6].find("ack") != std::string::npos ? BusEventKind::NoAcknowledge : BusEventKind::BusError;
        r.detail = "error on our frame, ECC 0x" + w[5] + (w[6] == "-" ? "" : ", " + w[6]);
        return r;
    }
    if (w[0] == "ERR" && w.size() >= 7) {
        r.event = BusEventKind::BusError;
        r.detail = "error while receiving, ECC 0x" + w[5];
        return r;
    }
    if (w[0] == "LOST" && w.size() >= 6 && w[5] == "1") {
        r.event = BusEventKind::ArbitrationLost;
        r.detail = "given up after losing arbitration at bit " + w[4];
        return r;
    }
    if (w[0] == "FAULT" && w.size() >= 5) {
        r.event = w[4] == "busoff" ? BusEventKind::BusOff : BusEventKind::ErrorPassive;
        r.detail = "forced by the lab";
        return r;
    }
    return std::nullopt; // SOF, IDLE, TXOK, JOIN, ...: the frames tell the story.
}

Received LabBusTransport::receive(std::chrono::milliseconds timeout, TransportError& error)
{
    if (!pending_.empty()) {
        Received next = pending_.front();
        pending_.pop_front();
        return next;
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
        const std::optional<std::string> line = readLine(deadline, error);
        if (!line) {
            return {};
        }
        std::optional<Received> event = parseEvent(*line, error);
        if (error) {
            return {};
        }
        if (event) {
            return *event;
        }
    }
}

} // namespace hostcan
