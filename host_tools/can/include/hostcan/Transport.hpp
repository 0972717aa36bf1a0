// One way to reach a CAN bus from a Linux host, behind one interface, so
// that every host tool takes `-i can0`, `-i slcan:/dev/ttyACM0`, `-i gsusb` or a lab bus
// alike and does the same thing with it (docs/guide/host-can.md).
//
// Transports hand over whole frames, with the time they were received and,
// where the transport reports them, the bus's error events (Linux's CAN
// error frames, an adapter's status flags). Errors are values: a transport
// never throws, and every wait has a time-out.
#pragma once

#include <can/CanFrame.hpp>

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace hostcan {

/// Why a transport call failed.
struct TransportError {
    enum class Kind {
        None,
        NotAvailable, ///< The kind of transport does not exist here (no PF_CAN in this kernel, no device).
        Open,         ///< The interface could not be opened or set up.
        Io,           ///< Reading or writing failed; the transport is probably unusable now.
        Closed,       ///< The other end went away.
        Refused,      ///< The interface refused the frame (full queue, bus-off, an adapter's BELL).
        Protocol,     ///< The other end sent something the transport cannot make sense of.
        BadArgument,  ///< The request itself is wrong (an unknown interface name, a bit rate the adapter lacks).
    };
    Kind kind = Kind::None;
    std::string message;

    explicit operator bool() const { return kind != Kind::None; }
};

/// The kind of a bus event a transport reports besides frames.
enum class BusEventKind : uint8_t {
    ErrorWarning,   ///< An error counter reached the warning limit.
    ErrorPassive,   ///< Error-passive entered.
    BusOff,         ///< The interface left the bus.
    Restarted,      ///< Back on the bus after bus-off.
    BusError,       ///< A bit, stuff, form, CRC or acknowledge error was seen.
    NoAcknowledge,  ///< Our frame was not acknowledged.
    ArbitrationLost,
    Overrun,        ///< Frames were lost in the interface.
    ErrorActive,    ///< Back to error-active.
};

const char* busEventName(BusEventKind kind);

/// What a receive returns: a frame, a bus event, or nothing before the time-out.
struct Received {
    enum class Kind { Frame, Event, Timeout };
    Kind kind = Kind::Timeout;
    can::CanFrame frame;
    BusEventKind event = BusEventKind::BusError;
    std::string detail;  ///< For events: what the interface said, e.g. "tx error counter 128".
    /// When the frame or event arrived: the kernel's timestamp for SocketCAN, the
    /// host's clock on arrival otherwise, or the bus's emulated time on the lab bus.
    std::chrono::nanoseconds timestamp{0};
    bool emulatedTime = false; ///< The timestamp is the lab's emulated time, exact.
};

class Transport {
public:
    virtual ~Transport() = default;

    /// The name the user gave, e.g. "can0" or "slcan:/dev/ttyACM0".
    virtual std::string name() const = 0;

    /// Sends one frame, waiting at most @p timeout for room in the interface.
    virtual TransportError send(const can::CanFrame& frame, std::chrono::milliseconds timeout) = 0;

    /// Waits at most @p timeout for the next frame or bus event.
    virtual Received receive(std::chrono::milliseconds timeout, TransportError& error) = 0;

    /// The interface's bit rate when the transport knows it, for bus load.
    virtual std::optional<uint32_t> bitRate() const = 0;

    /// Waits at most @p timeout until every frame sent has left the
    /// transport's own hands: Refused, saying how many, when some are still
    /// unconfirmed. A tool calls it before it ends, since closing some
    /// interfaces (a USB adapter's reset) takes queued frames off the bus.
    /// Transports whose frames outlive them (SocketCAN's kernel queue, an
    /// slcan adapter's) have nothing to wait for.
    virtual TransportError drain(std::chrono::milliseconds timeout)
    {
        (void)timeout;
        return {};
    }
};

/// Opens the transport a `-i` argument names:
///
///     can0, vcan0, slcan0 ...         SocketCAN network interface (raw socket, error frames on)
///     slcan:/dev/ttyACM0[@bitrate]    an slcan (Lawicel) adapter on a serial device, default 500000 bit/s
///     slcan-socket:/path[@bitrate]    an slcan adapter behind a unix socket (we play the host side)
///     gsusb[@bitrate]                 the first gs_usb adapter (candleLight, CANable) found by libusb, default 500000 bit/s
///     gsusb:<serial>[@bitrate]        the gs_usb adapter with that USB serial number (`dcos-can list`)
///     lab:/path/to/hub.sock:bus       a participant of the lab's CAN bus hub (docs/protocols/labbus.md)
///
/// BadArgument for a name of none of these forms; NotAvailable when the
/// device named is not there (no such serial device, no gs_usb adapter).
std::unique_ptr<Transport> openTransport(const std::string& spec, TransportError& error);

} // namespace hostcan
