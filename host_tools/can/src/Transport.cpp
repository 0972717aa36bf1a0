#include <hostcan/GsUsbTransport.hpp>
#include <hostcan/LabBusTransport.hpp>
#include <hostcan/SlcanTransport.hpp>
#include <hostcan/SocketCanTransport.hpp>
#include <hostcan/Transport.hpp>

#include <charconv>

namespace hostcan {

namespace {

constexpr uint32_t kDefaultSlcanBitRate = 500'000;

bool startsWith(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

// "path[@bitrate]" into its parts; false for a bit rate that is not a number.
bool splitBitRate(const std::string& text, std::string& path, uint32_t& bitRate)
{
    const size_t at = text.rfind('@');
    path = text.substr(0, at);
    bitRate = kDefaultSlcanBitRate;
    if (at == std::string::npos) {
        return !path.empty();
    }
    const std::string number = text.substr(at + 1);
    const auto [end, problem] = std::from_chars(number.data(), number.data() + number.size(), bitRate);
    return !path.empty() && problem == std::errc() && end == number.data() + number.size();
}

} // namespace

const char* busEventName(BusEventKind kind)
{
    switch (kind) {
    case BusEventKind::ErrorWarning: return "error-warning";
    case BusEventKind::ErrorPassive: return "error-passive";
    case BusEventKind::BusOff: return "bus-off";
    case BusEventKind::Restarted: return "restarted";
    case BusEventKind::BusError: return "bus-error";
    case BusEventKind::NoAcknowledge: return "no-acknowledge";
    case BusEventKind::ArbitrationLost: return "arbitration-lost";
    case BusEventKind::Overrun: return "overrun";
    case BusEventKind::ErrorActive: return "error-active";
    }
    return "unknown";
}

std::unique_ptr<Transport> openTransport(const std::string& spec, TransportError& error)
{
    for (const char* prefix : {"slcan:", "slcan-socket:"}) {
        if (startsWith(spec, prefix)) {
            std::string path;
            uint32_t bitRate = 0;
            if (!splitBitRate(spec.substr(std::string(prefix).size()), path, bitRate)) {
                error = {TransportError::Kind::BadArgument,
                         "'" + spec + "': write " + prefix + "<path>[@<bit rate>], e.g. " + prefix + "/dev/ttyACM0@500000"};
                return nullptr;
            }
            return SlcanTransport::open(path, std::string(prefix) == "slcan-socket:", bitRate, error);
        }
    }
    if (spec == "gsusb" || startsWith(spec, "gsusb:") || startsWith(spec, "gsusb@")) {
        const std::optional<GsUsbSpec> parsed = parseGsUsbSpec(spec, error);
        if (!parsed) {
            return nullptr;
        }
        return GsUsbTransport::open(parsed->serial, parsed->bitRate, parsed->name, error);
    }
    if (startsWith(spec, "lab:")) {
        // lab:<socket path>:<bus>; the path may hold colons, the bus name does not.
        const std::string rest = spec.substr(4);
        const size_t colon = rest.rfind(':');
        if (colon == std::string::npos || colon == 0 || colon + 1 == rest.size()) {
            error = {TransportError::Kind::BadArgument,
                     "'" + spec + "': write lab:<hub socket>:<bus>, e.g. lab:/tmp/lab.sock:can0"};
            return nullptr;
        }
        return LabBusTransport::open(rest.substr(0, colon), rest.substr(colon + 1), error);
    }
    if (spec.find(':') != std::string::npos || spec.find('/') != std::string::npos) {
        error = {TransportError::Kind::BadArgument,
                 "'" + spec + "' is not an interface: write a SocketCAN interface (can0), slcan:<device>[@<bit rate>], "
                              "slcan-socket:<path>[@<bit rate>], gsusb[:<serial>][@<bit rate>] or lab:<hub socket>:<bus>"};
        return nullptr;
    }
    return SocketCanTransport::open(spec, error);
}

} // namespace hostcan
