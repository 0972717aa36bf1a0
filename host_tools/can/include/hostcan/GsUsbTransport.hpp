// A gs_usb adapter (candleLight, CANable with candleLight firmware, the
// other devices of Linux's gs_usb table) as a transport, spoken to from user
// space through a GsUsbDevice: `-i gsusb:<serial>` works like `-i can0`
// without the kernel's gs_usb module (docs/protocols/gs_usb.md).
//
// Opening sends what Linux's driver sends when it probes the device and
// brings the interface up: HOST_FORMAT, DEVICE_CONFIG, BT_CONST, then the
// bit timing computed for the wanted rate, then MODE start on channel 0.
// Closing lets the frames still in flight reach the bus (bounded) and sends
// MODE reset, as Linux does when the interface goes down.
//
// Frames go out with an echo id; the adapter returns the frame with that id
// once it is on the bus. As in Linux's driver, at most ten are in flight; a
// send finding all ten unconfirmed waits for an echo within its time-out.
#pragma once

#include <hostcan/GsUsbDevice.hpp>
#include <hostcan/GsUsbProtocol.hpp>
#include <hostcan/Transport.hpp>

#include <array>
#include <deque>
#include <memory>
#include <optional>

namespace hostcan {

/// What `-i gsusb[:serial][@bitrate]` asks for.
struct GsUsbSpec {
    std::string name;     ///< The spec without the bit rate: "gsusb" or "gsusb:<serial>".
    std::string serial;   ///< Empty: the first adapter found.
    uint32_t bitRate = 0;
};

/// The bit rate an adapter is brought up at when the spec names none, as for slcan.
constexpr uint32_t kDefaultGsUsbBitRate = 500'000;

/// Parses `gsusb`, `gsusb@<rate>`, `gsusb:<serial>` or `gsusb:<serial>@<rate>`;
/// nothing and BadArgument, saying what to write, for anything else
/// (an empty serial, a rate that is no number or outside 1000..1000000).
std::optional<GsUsbSpec> parseGsUsbSpec(const std::string& spec, TransportError& error);

class GsUsbTransport final : public Transport {
public:
    /// How long the adapter has to answer a control request.
    static constexpr std::chrono::milliseconds kControlTimeout{1000};
    /// How long closing waits for the frames in flight to reach the bus.
    static constexpr std::chrono::milliseconds kCloseDrainTimeout{1000};
    /// The channel we bring up: the first, the only one most adapters have.
    static constexpr uint8_t kChannel = 0;
    /// Frames and events kept for receive() while a program only sends;
    /// past this the newest are dropped and an Overrun event says how many.
    static constexpr size_t kMaxPending = 65'536;

    /// What the transport counted and let pass without an error.
    struct Statistics {
        uint64_t unknownEchoes = 0;   ///< Echo ids we did not have in flight (an earlier program's frames).
        uint64_t otherChannel = 0;    ///< Frames of a channel we did not start.
        uint64_t malformed = 0;       ///< IN transfers refused (each also reported as a Protocol error).
        uint64_t dropped = 0;         ///< Received while kMaxPending were already waiting.
    };

    /// Finds the adapter with serial number @p serial (the first one when
    /// empty) through libusb and brings channel 0 onto the bus at @p bitRate.
    /// @p name is what name() returns, e.g. "gsusb:0037004A...".
    static std::unique_ptr<GsUsbTransport> open(const std::string& serial, uint32_t bitRate, std::string name,
                                                TransportError& error);

    /// Brings channel 0 of an opened device onto the bus at @p bitRate (the
    /// host tests hand a fake here). BadArgument when the adapter's clock
    /// and limits cannot make the rate; Closed when it goes away meanwhile;
    /// Refused when it stalls a request; Protocol when an answer is short.
    static std::unique_ptr<GsUsbTransport> adopt(std::unique_ptr<GsUsbDevice> device, std::string name,
                                                 uint32_t bitRate, TransportError& error);
    ~GsUsbTransport() override;

    std::string name() const override { return name_; }
    /// Queues @p frame with a free echo id; when all ten are in flight,
    /// waits at most @p timeout for the adapter to confirm one (Refused if
    /// none comes: no other node acknowledging, or the adapter is bus-off).
    TransportError send(const can::CanFrame& frame, std::chrono::milliseconds timeout) override;
    /// The next frame or bus event within @p timeout; Closed once the
    /// adapter is unplugged, Protocol for a transfer that makes no sense.
    Received receive(std::chrono::milliseconds timeout, TransportError& error) override;
    std::optional<uint32_t> bitRate() const override { return bitRate_; }
    /// Waits at most @p timeout for the echo of every frame in flight:
    /// Refused, with the count, for those the adapter did not confirm;
    /// frames and events that arrive meanwhile are kept for receive().
    TransportError drain(std::chrono::milliseconds timeout) override;

    /// The bit timing the adapter was set to.
    const gsusb::BitTimingChoice& timing() const { return timing_; }
    /// What DEVICE_CONFIG said.
    const gsusb::DeviceConfig& deviceConfig() const { return config_; }
    /// Frames sent whose echo has not come back yet.
    size_t framesInFlight() const;
    const Statistics& statistics() const { return statistics_; }

private:
    GsUsbTransport(std::unique_ptr<GsUsbDevice> device, std::string name, uint32_t bitRate)
        : device_(std::move(device)), name_(std::move(name)), bitRate_(bitRate)
    {
    }

    // One control request; the request's name goes into the messages.
    TransportError controlOut(gsusb::Request request, const char* what, uint16_t value, uint16_t index,
                              const std::vector<uint8_t>& data);
    TransportError controlIn(gsusb::Request request, const char* what, uint16_t value, uint16_t index,
                             std::vector<uint8_t>& answer);
    TransportError usbError(const UsbResult& result, const char* what);
    // Reads at most one IN transfer before @p deadline (always trying once):
    // echoes free their id, frames and events join pending_.
    TransportError pump(std::chrono::steady_clock::time_point deadline);
    void keep(Received received);

    std::unique_ptr<GsUsbDevice> device_;
    std::string name_;
    uint32_t bitRate_;
    gsusb::DeviceConfig config_;
    gsusb::BitTimingChoice timing_;
    std::array<bool, gsusb::kMaxEchoIds> inFlight_{};
    std::deque<Received> pending_;
    uint64_t droppedUnreported_ = 0;
    bool started_ = false;
    TransportError gone_; // Set once the adapter was unplugged; every later call returns it.
    Statistics statistics_;
};

} // namespace hostcan
