#include <hostcan/GsUsbProtocol.hpp>
#include <hostcan/SocketCanTransport.hpp>

#include <algorithm>
#include <cstdio>

namespace hostcan::gsusb {

namespace {

// Offsets inside struct gs_host_frame (gs_usb.c; packed, so each field
// follows the one before it without padding).
constexpr size_t kOffsetEchoId = 0;
constexpr size_t kOffsetCanId = 4;
constexpr size_t kOffsetDlc = 8;
constexpr size_t kOffsetChannel = 9;
constexpr size_t kOffsetFlags = 10;
constexpr size_t kOffsetReserved = 11;
constexpr size_t kOffsetData = 12;
constexpr size_t kOffsetTimestamp = 20; // struct classic_can_ts: after the 8 data bytes.

// No CAN controller counts more time quanta per bit than this (classic CAN
// needs 8 to 25; CAN FD controllers' nominal phase allows a few hundred).
// Limits above it, from a confused device, are clamped so the search stays
// short.
constexpr uint32_t kMaxSegmentQuanta = 1024;

uint32_t readLe32(const uint8_t* p)
{
    return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}

void appendLe32(std::vector<uint8_t>& out, uint32_t value)
{
    for (int shift = 0; shift < 32; shift += 8) {
        out.push_back(static_cast<uint8_t>(value >> shift));
    }
}

std::string tooShort(const char* what, size_t size, size_t needed)
{
    return std::string(what) + " of " + std::to_string(size) + " bytes, where " + std::to_string(needed) +
           " are needed";
}

Received frameReceived(const can::CanFrame& frame)
{
    Received r;
    r.kind = Received::Kind::Frame;
    r.frame = frame;
    return r;
}

Received eventReceived(BusEventKind kind, std::string detail)
{
    Received r;
    r.kind = Received::Kind::Event;
    r.event = kind;
    r.detail = std::move(detail);
    return r;
}

std::string hex32(uint32_t value)
{
    char text[16];
    std::snprintf(text, sizeof text, "0x%08X", value);
    return text;
}

} // namespace

std::vector<uint8_t> encodeHostConfig()
{
    std::vector<uint8_t> out;
    appendLe32(out, kHostByteOrder);
    return out;
}

Result<DeviceConfig> decodeDeviceConfig(const uint8_t* data, size_t size)
{
    if (data == nullptr || size < DeviceConfig::kSize) {
        return Result<DeviceConfig>::failure(tooShort("a device configuration", size, DeviceConfig::kSize));
    }
    DeviceConfig config;
    // Bytes 0..2 are reserved1..3, which devices leave zero and we ignore.
    config.icount = data[3];
    config.softwareVersion = readLe32(data + 4);
    config.hardwareVersion = readLe32(data + 8);
    return Result<DeviceConfig>::success(config);
}

std::vector<uint8_t> encodeDeviceConfig(const DeviceConfig& config)
{
    std::vector<uint8_t> out{0, 0, 0, config.icount};
    appendLe32(out, config.softwareVersion);
    appendLe32(out, config.hardwareVersion);
    return out;
}

Result<BitTimingConst> decodeBitTimingConst(const uint8_t* data, size_t size)
{
    if (data == nullptr || size < BitTimingConst::kSize) {
        return Result<BitTimingConst>::failure(tooShort("a bit timing description", size, BitTimingConst::kSize));
    }
    BitTimingConst c;
    c.feature = readLe32(data + 0);
    c.clockHz = readLe32(data + 4);
    c.tseg1Min = readLe32(data + 8);
    c.tseg1Max = readLe32(data + 12);
    c.tseg2Min = readLe32(data + 16);
    c.tseg2Max = readLe32(data + 20);
    c.sjwMax = readLe32(data + 24);
    c.brpMin = readLe32(data + 28);
    c.brpMax = readLe32(data + 32);
    c.brpIncrement = readLe32(data + 36);
    if (c.clockHz == 0) {
        return Result<BitTimingConst>::failure("a bit timing description with a CAN clock of 0 Hz");
    }
    if (c.tseg1Min > c.tseg1Max || c.tseg2Min > c.tseg2Max || c.brpMin > c.brpMax || c.tseg2Max == 0 ||
        c.brpMax == 0) {
        return Result<BitTimingConst>::failure("a bit timing description whose limits are empty (tseg1 " +
                                               std::to_string(c.tseg1Min) + ".." + std::to_string(c.tseg1Max) +
                                               ", tseg2 " + std::to_string(c.tseg2Min) + ".." +
                                               std::to_string(c.tseg2Max) + ", brp " + std::to_string(c.brpMin) +
                                               ".." + std::to_string(c.brpMax) + ")");
    }
    // Linux's can_calc_bittiming steps the prescaler by brp_inc; a device
    // that says 0 means "any", which is a step of 1.
    if (c.brpIncrement == 0) {
        c.brpIncrement = 1;
    }
    return Result<BitTimingConst>::success(c);
}

std::vector<uint8_t> encodeBitTimingConst(const BitTimingConst& c)
{
    std::vector<uint8_t> out;
    for (uint32_t value : {c.feature, c.clockHz, c.tseg1Min, c.tseg1Max, c.tseg2Min, c.tseg2Max, c.sjwMax, c.brpMin,
                           c.brpMax, c.brpIncrement}) {
        appendLe32(out, value);
    }
    return out;
}

std::vector<uint8_t> encodeBitTiming(const BitTiming& t)
{
    std::vector<uint8_t> out;
    for (uint32_t value : {t.propSeg, t.phaseSeg1, t.phaseSeg2, t.sjw, t.brp}) {
        appendLe32(out, value);
    }
    return out;
}

Result<BitTiming> decodeBitTiming(const uint8_t* data, size_t size)
{
    if (data == nullptr || size < BitTiming::kSize) {
        return Result<BitTiming>::failure(tooShort("a bit timing", size, BitTiming::kSize));
    }
    BitTiming t;
    t.propSeg = readLe32(data + 0);
    t.phaseSeg1 = readLe32(data + 4);
    t.phaseSeg2 = readLe32(data + 8);
    t.sjw = readLe32(data + 12);
    t.brp = readLe32(data + 16);
    return Result<BitTiming>::success(t);
}

std::vector<uint8_t> encodeDeviceMode(const DeviceMode& mode)
{
    std::vector<uint8_t> out;
    appendLe32(out, mode.mode);
    appendLe32(out, mode.flags);
    return out;
}

Result<DeviceMode> decodeDeviceMode(const uint8_t* data, size_t size)
{
    if (data == nullptr || size < DeviceMode::kSize) {
        return Result<DeviceMode>::failure(tooShort("a device mode", size, DeviceMode::kSize));
    }
    DeviceMode mode;
    mode.mode = readLe32(data);
    mode.flags = readLe32(data + 4);
    return Result<DeviceMode>::success(mode);
}

std::vector<uint8_t> encodeHostFrame(const HostFrame& frame)
{
    std::vector<uint8_t> out;
    // echo_id is opaque to the device, which returns it as it came; we
    // write it little-endian like every other field, so that 0xFFFFFFFF
    // and the ids 0..9 look the same in either order anyway.
    appendLe32(out, frame.echoId);
    appendLe32(out, frame.canId);
    out.push_back(frame.dlc);
    out.push_back(frame.channel);
    out.push_back(frame.flags);
    out.push_back(frame.reserved);
    out.insert(out.end(), frame.data, frame.data + 8);
    if (frame.hasTimestamp) {
        appendLe32(out, frame.timestampUs);
    }
    return out;
}

Result<HostFrame> decodeHostFrame(const uint8_t* data, size_t size, bool timestamps)
{
    const size_t needed = timestamps ? kHostFrameTimestampedSize : kHostFrameSize;
    if (data == nullptr || size < needed) {
        return Result<HostFrame>::failure(tooShort("a transfer", size, needed));
    }
    HostFrame frame;
    frame.echoId = readLe32(data + kOffsetEchoId);
    frame.canId = readLe32(data + kOffsetCanId);
    frame.dlc = data[kOffsetDlc];
    frame.channel = data[kOffsetChannel];
    frame.flags = data[kOffsetFlags];
    frame.reserved = data[kOffsetReserved];
    std::copy(data + kOffsetData, data + kOffsetData + 8, frame.data);
    if ((frame.flags & kFrameFlagFd) != 0) {
        // A CAN FD host frame carries 64 data bytes; the channel was started
        // without GS_CAN_MODE_FD, so the device should never send one.
        char flags[8];
        std::snprintf(flags, sizeof flags, "0x%02X", frame.flags);
        return Result<HostFrame>::failure(std::string("a CAN FD host frame (flags ") + flags +
                                          "), though the channel was started for classic CAN only");
    }
    if (timestamps) {
        frame.hasTimestamp = true;
        frame.timestampUs = readLe32(data + kOffsetTimestamp);
    }
    return Result<HostFrame>::success(frame);
}

HostFrame hostFrameFor(const can::CanFrame& frame, uint32_t echoId, uint8_t channel)
{
    HostFrame out;
    out.echoId = echoId;
    out.canId = frame.id();
    if (frame.isExtended()) {
        out.canId |= kCanIdExtendedFlag;
    }
    if (frame.isRemote()) {
        out.canId |= kCanIdRemoteFlag;
    }
    out.dlc = frame.length();
    out.channel = channel;
    // A remote frame's data bytes are zero in a CanFrame, so they go as zeros.
    std::copy(frame.data(), frame.data() + 8, out.data);
    return out;
}

Result<can::CanFrame> canFrameOf(const HostFrame& frame)
{
    if ((frame.canId & kCanIdErrorFlag) != 0) {
        return Result<can::CanFrame>::failure("an error frame, which is no bus frame");
    }
    if (frame.dlc > can::CanFrame::kMaxDataLength) {
        return Result<can::CanFrame>::failure("a data length code of " + std::to_string(frame.dlc) +
                                              ", where DCOS takes 0 to 8");
    }
    const bool extended = (frame.canId & kCanIdExtendedFlag) != 0;
    const bool remote = (frame.canId & kCanIdRemoteFlag) != 0;
    const uint32_t id = frame.canId & kCanIdExtendedMask;
    if (!extended && id > kCanIdStandardMask) {
        return Result<can::CanFrame>::failure("a standard identifier " + hex32(id) + " wider than 11 bits");
    }
    const can::IdFormat format = extended ? can::IdFormat::Extended : can::IdFormat::Standard;
    const can::LinkResult<can::CanFrame> made = remote ? can::CanFrame::makeRemote(id, format, frame.dlc)
                                                       : can::CanFrame::makeData(id, format, frame.data, frame.dlc);
    if (!made.ok()) {
        return Result<can::CanFrame>::failure(std::string("a frame the link layer refuses: ") +
                                              can::linkErrorName(made.error()));
    }
    return Result<can::CanFrame>::success(made.value());
}

Result<InTransfer> decodeInTransfer(const uint8_t* data, size_t size, bool timestamps, unsigned channels)
{
    const Result<HostFrame> decoded = decodeHostFrame(data, size, timestamps);
    if (!decoded.ok()) {
        return Result<InTransfer>::failure(decoded.reason());
    }
    const HostFrame& frame = decoded.value();
    if (frame.channel >= channels) {
        // gs_usb.c takes the whole device down on this; we refuse the transfer.
        return Result<InTransfer>::failure("a host frame for channel " + std::to_string(frame.channel) +
                                           " of an interface with " + std::to_string(channels) + " channel" +
                                           (channels == 1 ? "" : "s"));
    }
    InTransfer out;
    out.channel = frame.channel;
    if (frame.echoId != kEchoIdReceived) {
        // The echo carries our frame back; its content is ours, so only the id counts.
        out.isEcho = true;
        out.echoId = frame.echoId;
    } else if ((frame.canId & kCanIdErrorFlag) != 0) {
        // The devices put Linux's error frame in the host frame unchanged
        // (gs_usb.c passes it up as it is), so SocketCAN's reading applies.
        LinuxErrorFrame error;
        error.canId = frame.canId;
        std::copy(frame.data, frame.data + 8, error.data);
        out.received = decodeErrorFrame(error);
        if (out.received.empty()) {
            out.received.push_back(eventReceived(BusEventKind::BusError, "unclassified error frame (can_id " +
                                                                             hex32(frame.canId) + ")"));
        }
    } else {
        const Result<can::CanFrame> canFrame = canFrameOf(frame);
        if (!canFrame.ok()) {
            return Result<InTransfer>::failure(canFrame.reason());
        }
        out.received.push_back(frameReceived(canFrame.value()));
    }
    if ((frame.flags & kFrameFlagOverflow) != 0) {
        // gs_usb.c turns the flag into CAN_ERR_CRTL_RX_OVERFLOW.
        out.received.push_back(eventReceived(BusEventKind::Overrun, "the adapter lost received frames (overflow)"));
    }
    return Result<InTransfer>::success(std::move(out));
}

Result<BitTimingChoice> computeBitTiming(uint32_t bitRate, const BitTimingConst& limits)
{
    using R = Result<BitTimingChoice>;
    if (bitRate < kMinBitRate || bitRate > kMaxBitRate) {
        return R::failure("a bit rate of " + std::to_string(bitRate) + " bit/s is outside " +
                          std::to_string(kMinBitRate) + " to " + std::to_string(kMaxBitRate) +
                          " bit/s, the classic CAN rates we drive an adapter at");
    }
    if (limits.clockHz == 0 || limits.brpMin > limits.brpMax || limits.tseg1Min > limits.tseg1Max ||
        limits.tseg2Min > limits.tseg2Max) {
        return R::failure("the adapter's bit timing limits are empty");
    }
    const uint64_t clock = limits.clockHz;
    const uint64_t tseg1Min = std::max<uint32_t>(limits.tseg1Min, 1);
    const uint64_t tseg1Max = std::min<uint32_t>(limits.tseg1Max, kMaxSegmentQuanta);
    const uint64_t tseg2Min = std::max<uint32_t>(limits.tseg2Min, 1);
    const uint64_t tseg2Max = std::min<uint32_t>(limits.tseg2Max, kMaxSegmentQuanta);
    const uint64_t brpMin = std::max<uint32_t>(limits.brpMin, 1);
    const uint64_t brpMax = limits.brpMax;
    const uint64_t brpStep = std::max<uint32_t>(limits.brpIncrement, 1);
    const uint64_t minQuanta = 1 + tseg1Min + tseg2Min;
    const uint64_t maxQuanta = 1 + tseg1Max + tseg2Max;
    const uint64_t rate = bitRate;

    // Prescalers below this give more quanta per bit than the segments hold;
    // start there (on the brp_inc grid) rather than count up from brp_min.
    uint64_t brp = brpMin;
    const uint64_t firstUseful = clock / (rate * (maxQuanta + 1));
    if (firstUseful > brpMin) {
        brp = brpMin + (firstUseful - brpMin) / brpStep * brpStep;
    }

    bool found = false;
    BitTimingChoice best;
    uint64_t bestRateError = 0;
    uint64_t bestSampleError = 0;
    for (; brp <= brpMax; brp += brpStep) {
        const uint64_t perBit = brp * rate;
        const uint64_t quanta = (clock + perBit / 2) / perBit;
        if (quanta < minQuanta) {
            break; // Quanta only shrink as the prescaler grows.
        }
        if (quanta > maxQuanta) {
            continue;
        }
        const uint64_t made = brp * quanta * rate;
        const uint64_t rateError = (clock > made ? clock - made : made - clock) * 1'000'000 / made;
        if (rateError > kMaxBitRateErrorPpm) {
            continue;
        }
        // tseg1 for the sample point nearest 87.5 %, then into the range the
        // limits leave it; the error grows monotonically away from the ideal,
        // so the nearest allowed value is the best one.
        const uint64_t ideal = (quanta * kSamplePointPermille + 500) / 1000;
        const uint64_t low = std::max(tseg1Min, quanta > 1 + tseg2Max ? quanta - 1 - tseg2Max : 0);
        const uint64_t high = std::min(tseg1Max, quanta - 1 - tseg2Min);
        if (low > high) {
            continue;
        }
        const uint64_t tseg1 = std::clamp(ideal >= 1 ? ideal - 1 : 0, low, high);
        const uint64_t tseg2 = quanta - 1 - tseg1;
        const uint64_t samplePpm = (1 + tseg1) * 1'000'000 / quanta;
        const uint64_t sampleError =
            samplePpm > kSamplePointPermille * 1000 ? samplePpm - kSamplePointPermille * 1000
                                                    : kSamplePointPermille * 1000 - samplePpm;
        if (found && (rateError > bestRateError || (rateError == bestRateError && sampleError >= bestSampleError))) {
            continue;
        }
        found = true;
        bestRateError = rateError;
        bestSampleError = sampleError;
        best.timing.brp = static_cast<uint32_t>(brp);
        best.timing.propSeg = static_cast<uint32_t>(tseg1 / 2);
        best.timing.phaseSeg1 = static_cast<uint32_t>(tseg1 - tseg1 / 2);
        best.timing.phaseSeg2 = static_cast<uint32_t>(tseg2);
        const uint64_t sjw = std::min<uint64_t>({std::max<uint32_t>(limits.sjwMax, 1), best.timing.phaseSeg1, tseg2});
        best.timing.sjw = static_cast<uint32_t>(std::max<uint64_t>(sjw, 1));
        best.quanta = static_cast<uint32_t>(quanta);
        best.bitRate = static_cast<uint32_t>((clock + brp * quanta / 2) / (brp * quanta));
        best.samplePointPermille = static_cast<uint32_t>(((1 + tseg1) * 1000 + quanta / 2) / quanta);
    }
    if (!found) {
        return R::failure("no bit timing makes " + std::to_string(bitRate) + " bit/s (within 0.1 %) from the adapter's " +
                          std::to_string(limits.clockHz) + " Hz clock with tseg1 " + std::to_string(limits.tseg1Min) +
                          ".." + std::to_string(limits.tseg1Max) + ", tseg2 " + std::to_string(limits.tseg2Min) +
                          ".." + std::to_string(limits.tseg2Max) + " and a prescaler of " +
                          std::to_string(limits.brpMin) + ".." + std::to_string(limits.brpMax));
    }
    return R::success(best);
}

} // namespace hostcan::gsusb
