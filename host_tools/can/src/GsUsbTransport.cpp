#include <hostcan/GsUsbTransport.hpp>
#include <hostcan/LibUsbGsDevice.hpp>

#include <algorithm>
#include <charconv>

namespace hostcan {

namespace {

using Clock = std::chrono::steady_clock;

std::chrono::nanoseconds now()
{
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch());
}

// The least time a bulk OUT transfer is given (see send()).
constexpr std::chrono::milliseconds kMinOutTimeout{10};

// The time left before @p deadline, at least 1 ms, so every wait asks the
// adapter at least once (a receive with a time-out of 0 still polls).
std::chrono::milliseconds left(Clock::time_point deadline)
{
    const auto remaining = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    return std::max(remaining, std::chrono::milliseconds(1));
}

const char* kSpecForms = "write gsusb, gsusb@<bit rate>, gsusb:<serial> or gsusb:<serial>@<bit rate>, "
                         "e.g. gsusb:0037004A5346500B20363751@500000 (`dcos-can list` shows the serial numbers)";

} // namespace

std::optional<GsUsbSpec> parseGsUsbSpec(const std::string& spec, TransportError& error)
{
    static const std::string kPrefix = "gsusb";
    const auto bad = [&](const std::string& why) {
        error = {TransportError::Kind::BadArgument, "'" + spec + "': " + why + "; " + kSpecForms};
        return std::nullopt;
    };
    if (spec.rfind(kPrefix, 0) != 0) {
        return bad("not a gs_usb adapter");
    }
    std::string rest = spec.substr(kPrefix.size());
    GsUsbSpec parsed;
    parsed.bitRate = kDefaultGsUsbBitRate;
    const size_t at = rest.rfind('@');
    if (at != std::string::npos) {
        const std::string number = rest.substr(at + 1);
        uint32_t rate = 0;
        const auto [end, problem] = std::from_chars(number.data(), number.data() + number.size(), rate);
        if (number.empty() || problem != std::errc() || end != number.data() + number.size()) {
            return bad("'" + number + "' is not a bit rate");
        }
        if (rate < gsusb::kMinBitRate || rate > gsusb::kMaxBitRate) {
            return bad("a bit rate of " + number + " bit/s is outside " + std::to_string(gsusb::kMinBitRate) +
                       " to " + std::to_string(gsusb::kMaxBitRate));
        }
        parsed.bitRate = rate;
        rest = rest.substr(0, at);
    }
    if (!rest.empty()) {
        if (rest[0] != ':') {
            return bad("not a gs_usb adapter");
        }
        parsed.serial = rest.substr(1);
        if (parsed.serial.empty()) {
            return bad("the serial number is missing");
        }
        for (char c : parsed.serial) {
            // USB serial number strings are printable; anything else is a typing slip.
            if (c <= ' ' || c > '~') {
                return bad("a serial number holds printable characters only");
            }
        }
    }
    parsed.name = kPrefix + (parsed.serial.empty() ? "" : ":" + parsed.serial);
    return parsed;
}

std::unique_ptr<GsUsbTransport> GsUsbTransport::open(const std::string& serial, uint32_t bitRate, std::string name,
                                                     TransportError& error)
{
    std::unique_ptr<LibUsbGsDevice> device = LibUsbGsDevice::open(serial, error);
    if (!device) {
        return nullptr;
    }
    return adopt(std::move(device), std::move(name), bitRate, error);
}

std::unique_ptr<GsUsbTransport> GsUsbTransport::adopt(std::unique_ptr<GsUsbDevice> device, std::string name,
                                                      uint32_t bitRate, TransportError& error)
{
    using namespace gsusb;
    const uint16_t interface = device->interfaceNumber();
    std::unique_ptr<GsUsbTransport> transport(new GsUsbTransport(std::move(device), std::move(name), bitRate));
    // The order and the arguments of Linux's gs_usb_probe(), gs_make_candev(),
    // gs_usb_set_bittiming() and gs_can_open().
    if (TransportError e = transport->controlOut(Request::HostFormat, "HOST_FORMAT", kInterfaceRequestValue,
                                                 interface, encodeHostConfig())) {
        error = e;
        return nullptr;
    }
    std::vector<uint8_t> answer(DeviceConfig::kSize);
    if (TransportError e = transport->controlIn(Request::DeviceConfig, "DEVICE_CONFIG", kInterfaceRequestValue,
                                                interface, answer)) {
        error = e;
        return nullptr;
    }
    const Result<DeviceConfig> config = decodeDeviceConfig(answer.data(), answer.size());
    if (!config.ok()) {
        error = {TransportError::Kind::Protocol, transport->name_ + ": DEVICE_CONFIG answered " + config.reason()};
        return nullptr;
    }
    transport->config_ = config.value();
    answer.assign(BitTimingConst::kSize, 0);
    if (TransportError e = transport->controlIn(Request::BitTimingConst, "BT_CONST", kChannel, 0, answer)) {
        error = e;
        return nullptr;
    }
    const Result<BitTimingConst> limits = decodeBitTimingConst(answer.data(), answer.size());
    if (!limits.ok()) {
        error = {TransportError::Kind::Protocol, transport->name_ + ": BT_CONST answered " + limits.reason()};
        return nullptr;
    }
    const Result<BitTimingChoice> timing = computeBitTiming(bitRate, limits.value());
    if (!timing.ok()) {
        error = {TransportError::Kind::BadArgument, transport->name_ + ": " + timing.reason()};
        return nullptr;
    }
    transport->timing_ = timing.value();
    if (TransportError e = transport->controlOut(Request::BitTiming, "BITTIMING", kChannel, 0,
                                                 encodeBitTiming(timing.value().timing))) {
        error = e;
        return nullptr;
    }
    DeviceMode start;
    start.mode = kModeStart;
    start.flags = kModeFlagNormal;
    if (TransportError e = transport->controlOut(Request::Mode, "MODE start", kChannel, 0, encodeDeviceMode(start))) {
        error = e;
        return nullptr;
    }
    transport->started_ = true;
    return transport;
}

GsUsbTransport::~GsUsbTransport()
{
    if (!started_ || gone_) {
        return;
    }
    // Frames in flight are in the adapter's mailboxes; a reset now would
    // take them off the bus, so give them a bounded moment first.
    const auto deadline = Clock::now() + kCloseDrainTimeout;
    while (framesInFlight() > 0 && Clock::now() < deadline) {
        if (pump(deadline).kind == TransportError::Kind::Closed) {
            return;
        }
    }
    gsusb::DeviceMode reset;
    reset.mode = gsusb::kModeReset;
    (void)controlOut(gsusb::Request::Mode, "MODE reset", kChannel, 0, gsusb::encodeDeviceMode(reset));
}

size_t GsUsbTransport::framesInFlight() const
{
    return static_cast<size_t>(std::count(inFlight_.begin(), inFlight_.end(), true));
}

TransportError GsUsbTransport::usbError(const UsbResult& result, const char* what)
{
    switch (result.status) {
    case UsbResult::Status::Ok: return {};
    case UsbResult::Status::NoDevice:
        gone_ = {TransportError::Kind::Closed, name_ + ": the adapter was unplugged"};
        return gone_;
    case UsbResult::Status::Timeout:
        return {TransportError::Kind::Protocol, name_ + ": the adapter did not complete " + what + " within its time-out"};
    case UsbResult::Status::Stall:
        return {TransportError::Kind::Refused, name_ + ": the adapter refused " + what + " (stall)"};
    case UsbResult::Status::Overflow:
        return {TransportError::Kind::Protocol, name_ + ": the adapter sent more than asked for in " + what};
    case UsbResult::Status::Io: break;
    }
    return {TransportError::Kind::Io, name_ + ": " + what + " failed: " + result.message};
}

TransportError GsUsbTransport::controlOut(gsusb::Request request, const char* what, uint16_t value, uint16_t index,
                                          const std::vector<uint8_t>& data)
{
    const UsbResult r =
        device_->controlOut(static_cast<uint8_t>(request), value, index, data.data(), data.size(), kControlTimeout);
    if (!r.ok()) {
        return usbError(r, what);
    }
    if (r.length != data.size()) {
        return {TransportError::Kind::Protocol, name_ + ": the adapter took " + std::to_string(r.length) + " of the " +
                                                    std::to_string(data.size()) + " bytes of " + what};
    }
    return {};
}

TransportError GsUsbTransport::controlIn(gsusb::Request request, const char* what, uint16_t value, uint16_t index,
                                         std::vector<uint8_t>& answer)
{
    const UsbResult r = device_->controlIn(static_cast<uint8_t>(request), value, index, answer.data(), answer.size(),
                                           kControlTimeout);
    if (!r.ok()) {
        return usbError(r, what);
    }
    // A short answer is kept short, for the decoder to refuse with its length.
    answer.resize(std::min(r.length, answer.size()));
    return {};
}

void GsUsbTransport::keep(Received received)
{
    if (pending_.size() >= kMaxPending) {
        ++statistics_.dropped;
        ++droppedUnreported_;
        return;
    }
    received.timestamp = now();
    pending_.push_back(std::move(received));
}

TransportError GsUsbTransport::pump(Clock::time_point deadline)
{
    if (gone_) {
        return gone_;
    }
    std::vector<uint8_t> buffer(std::max(device_->inPacketSize(), gsusb::kHostFrameSize));
    const UsbResult r = device_->bulkIn(buffer.data(), buffer.size(), left(deadline));
    if (r.status == UsbResult::Status::Timeout && r.length == 0) {
        return {};
    }
    if (r.status != UsbResult::Status::Ok && r.status != UsbResult::Status::Timeout) {
        return usbError(r, "reading from the adapter");
    }
    const gsusb::Result<gsusb::InTransfer> transfer =
        gsusb::decodeInTransfer(buffer.data(), r.length, false, config_.channels());
    if (!transfer.ok()) {
        ++statistics_.malformed;
        return {TransportError::Kind::Protocol,
                name_ + ": the adapter sent a transfer that makes no sense: " + transfer.reason()};
    }
    const gsusb::InTransfer& in = transfer.value();
    if (in.channel != kChannel) {
        ++statistics_.otherChannel;
        return {};
    }
    if (in.isEcho) {
        if (in.echoId < inFlight_.size() && inFlight_[in.echoId]) {
            inFlight_[in.echoId] = false;
        } else {
            // Linux's driver logs and drops these too: an echo of a frame an
            // earlier program sent, still queued in the adapter.
            ++statistics_.unknownEchoes;
        }
    }
    for (const Received& received : in.received) {
        keep(received);
    }
    return {};
}

TransportError GsUsbTransport::send(const can::CanFrame& frame, std::chrono::milliseconds timeout)
{
    if (gone_) {
        return gone_;
    }
    const auto deadline = Clock::now() + timeout;
    while (framesInFlight() >= inFlight_.size()) {
        if (Clock::now() >= deadline) {
            return {TransportError::Kind::Refused,
                    name_ + ": the adapter has confirmed none of the last " + std::to_string(inFlight_.size()) +
                        " frames within " + std::to_string(timeout.count()) +
                        " ms (is any other node acknowledging them? is the adapter bus-off?)"};
        }
        if (TransportError e = pump(deadline)) {
            return e;
        }
    }
    const auto free = std::find(inFlight_.begin(), inFlight_.end(), false);
    const uint32_t echoId = static_cast<uint32_t>(free - inFlight_.begin());
    const std::vector<uint8_t> bytes = gsusb::encodeHostFrame(gsusb::hostFrameFor(frame, echoId, kChannel));
    // One OUT transfer takes a USB frame or two even when the adapter has
    // room, so a time-out shorter than that would refuse a frame for nothing.
    const UsbResult r = device_->bulkOut(bytes.data(), bytes.size(), std::max(left(deadline), kMinOutTimeout));
    if (r.status == UsbResult::Status::Timeout && r.length == 0) {
        return {TransportError::Kind::Refused,
                name_ + ": the adapter did not take the frame within " + std::to_string(timeout.count()) + " ms"};
    }
    if (!r.ok()) {
        return usbError(r, "sending a frame");
    }
    if (r.length != bytes.size()) {
        return {TransportError::Kind::Io, name_ + ": the adapter took " + std::to_string(r.length) + " of the " +
                                              std::to_string(bytes.size()) + " bytes of a frame"};
    }
    *free = true;
    return {};
}

TransportError GsUsbTransport::drain(std::chrono::milliseconds timeout)
{
    const auto deadline = Clock::now() + timeout;
    while (framesInFlight() > 0) {
        if (gone_) {
            return gone_;
        }
        if (Clock::now() >= deadline) {
            return {TransportError::Kind::Refused,
                    name_ + ": the adapter confirmed " + std::to_string(framesInFlight()) +
                        (framesInFlight() == 1 ? " frame" : " frames") + " not within " +
                        std::to_string(timeout.count()) + " ms (is any other node acknowledging them?)"};
        }
        if (TransportError e = pump(deadline)) {
            return e;
        }
    }
    return {};
}

Received GsUsbTransport::receive(std::chrono::milliseconds timeout, TransportError& error)
{
    const auto deadline = Clock::now() + timeout;
    for (;;) {
        if (droppedUnreported_ > 0) {
            Received r;
            r.kind = Received::Kind::Event;
            r.event = BusEventKind::Overrun;
            r.detail = std::to_string(droppedUnreported_) + " frames dropped while the program was not reading";
            r.timestamp = now();
            droppedUnreported_ = 0;
            return r;
        }
        if (!pending_.empty()) {
            Received next = std::move(pending_.front());
            pending_.pop_front();
            return next;
        }
        if (gone_) {
            error = gone_;
            return {};
        }
        if (TransportError e = pump(deadline)) {
            error = e;
            return {};
        }
        if (pending_.empty() && droppedUnreported_ == 0 && Clock::now() >= deadline) {
            return {};
        }
    }
}

} // namespace hostcan
