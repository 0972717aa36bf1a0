// The gs_usb protocol (Geschwister Schneider USB/CAN, candleLight, CANable
// with candleLight firmware) as a pure codec: the vendor control requests'
// structures, the bulk transfers' host frames, and the bit timing the host
// computes for the adapter. No USB here, so all of it is tested on the host
// and fuzzed (docs/protocols/gs_usb.md).
//
// The facts come from Linux's driver, drivers/net/can/usb/gs_usb.c (the
// request numbers, the structures and their little-endian fields, the flags,
// the identifier table), and from the candleLight firmware that speaks the
// device side (include/gs_usb.h there carries the same definitions). The
// CAN identifier flags and error-frame bytes are Linux's own, from
// include/uapi/linux/can.h and include/uapi/linux/can/error.h, which the
// devices use unchanged.
//
// Every decoder takes the bytes as they came and refuses short or malformed
// input with the reason, as a value; nothing here throws.
#pragma once

#include <hostcan/Transport.hpp>

#include <can/CanFrame.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hostcan::gsusb {

/// A decoded value or the reason the input was refused.
template <typename T>
class Result {
public:
    /// A value.
    static Result success(T value)
    {
        Result r;
        r.value_ = std::move(value);
        r.ok_ = true;
        return r;
    }
    /// A refusal with its reason, a sentence fragment such as "12 bytes, a host frame has 20".
    static Result failure(std::string reason)
    {
        Result r;
        r.reason_ = std::move(reason);
        return r;
    }

    bool ok() const { return ok_; }
    /// The value; meaningful only when ok().
    const T& value() const { return value_; }
    /// Why the input was refused; empty when ok().
    const std::string& reason() const { return reason_; }

private:
    Result() = default;
    T value_{};
    std::string reason_;
    bool ok_ = false;
};

// ---------------------------------------------------------------------------
// Control requests (Linux gs_usb.c, enum gs_usb_breq; candleLight gs_usb.h).

/// The vendor requests' bRequest numbers.
enum class Request : uint8_t {
    HostFormat = 0,   ///< GS_USB_BREQ_HOST_FORMAT: the host's byte order (struct gs_host_config).
    BitTiming = 1,    ///< GS_USB_BREQ_BITTIMING: a channel's bit timing (struct gs_device_bittiming).
    Mode = 2,         ///< GS_USB_BREQ_MODE: start or reset a channel (struct gs_device_mode).
    BusErrors = 3,    ///< GS_USB_BREQ_BERR: not used by Linux nor by us.
    BitTimingConst = 4, ///< GS_USB_BREQ_BT_CONST: a channel's clock and timing limits (struct gs_device_bt_const).
    DeviceConfig = 5, ///< GS_USB_BREQ_DEVICE_CONFIG: channel count and versions (struct gs_device_config).
    Timestamp = 6,    ///< GS_USB_BREQ_TIMESTAMP: the device's microsecond clock; not used by us.
    Identify = 7,     ///< GS_USB_BREQ_IDENTIFY: blink the LEDs (struct gs_identify_mode).
};

/// bmRequestType of a request from host to device: USB_DIR_OUT (0x00) |
/// USB_TYPE_VENDOR (0x40) | USB_RECIP_INTERFACE (0x01), as gs_usb.c sends them
/// (USB 2.0 specification, table 9-2).
constexpr uint8_t kRequestTypeOut = 0x41;
/// bmRequestType of a request from device to host: USB_DIR_IN (0x80) | vendor | interface.
constexpr uint8_t kRequestTypeIn = 0xC1;

/// wValue of HOST_FORMAT and DEVICE_CONFIG, which concern the whole
/// interface rather than a channel: gs_usb.c's probe passes 1. Their wIndex
/// is the interface number; the channel requests (BITTIMING, MODE, BT_CONST,
/// IDENTIFY) pass the channel in wValue and 0 in wIndex.
constexpr uint16_t kInterfaceRequestValue = 1;

/// gs_host_config.byte_order: the value gs_usb.c sends, little-endian, so a
/// device that honours it (the original USB2CAN) answers little-endian too.
/// candleLight ignores it and is always little-endian.
constexpr uint32_t kHostByteOrder = 0x0000BEEF;

/// gs_device_mode.mode (enum gs_can_mode).
constexpr uint32_t kModeReset = 0; ///< GS_CAN_MODE_RESET: the channel stops.
constexpr uint32_t kModeStart = 1; ///< GS_CAN_MODE_START: the channel joins the bus.

/// gs_device_mode.flags (GS_CAN_MODE_*); we start with none of them (normal mode).
constexpr uint32_t kModeFlagNormal = 0;
constexpr uint32_t kModeFlagListenOnly = 1u << 0;   ///< GS_CAN_MODE_LISTEN_ONLY.
constexpr uint32_t kModeFlagLoopBack = 1u << 1;     ///< GS_CAN_MODE_LOOP_BACK.
constexpr uint32_t kModeFlagTripleSample = 1u << 2; ///< GS_CAN_MODE_TRIPLE_SAMPLE.
constexpr uint32_t kModeFlagOneShot = 1u << 3;      ///< GS_CAN_MODE_ONE_SHOT.
constexpr uint32_t kModeFlagHwTimestamp = 1u << 4;  ///< GS_CAN_MODE_HW_TIMESTAMP: host frames carry 4 more bytes.
constexpr uint32_t kModeFlagPadPackets = 1u << 7;   ///< GS_CAN_MODE_PAD_PKTS_TO_MAX_PKT_SIZE.
constexpr uint32_t kModeFlagFd = 1u << 8;           ///< GS_CAN_MODE_FD.

/// gs_device_bt_const.feature bits (GS_CAN_FEATURE_*), reported by `dcos-can list`.
constexpr uint32_t kFeatureListenOnly = 1u << 0;
constexpr uint32_t kFeatureLoopBack = 1u << 1;
constexpr uint32_t kFeatureTripleSample = 1u << 2;
constexpr uint32_t kFeatureOneShot = 1u << 3;
constexpr uint32_t kFeatureHwTimestamp = 1u << 4;
constexpr uint32_t kFeatureIdentify = 1u << 5;
constexpr uint32_t kFeatureFd = 1u << 8;

// ---------------------------------------------------------------------------
// Bulk transfers: struct gs_host_frame.

/// gs_host_frame.echo_id of a frame the device received from the bus
/// (gs_usb.c compares it with -1); any other value is the echo of a frame
/// the host sent, carrying the echo_id the host gave it.
constexpr uint32_t kEchoIdReceived = 0xFFFFFFFF;
/// How many frames Linux keeps in flight per channel (GS_MAX_TX_URBS), so
/// echo ids 0..9 are the ones every device has been tested with.
constexpr uint32_t kMaxEchoIds = 10;

/// gs_host_frame.flags (GS_CAN_FLAG_*).
constexpr uint8_t kFrameFlagOverflow = 1u << 0; ///< GS_CAN_FLAG_OVERFLOW: the device lost received frames.
constexpr uint8_t kFrameFlagFd = 1u << 1;       ///< GS_CAN_FLAG_FD: a CAN FD frame (64 data bytes follow).
constexpr uint8_t kFrameFlagBrs = 1u << 2;      ///< GS_CAN_FLAG_BRS: FD bit rate switch.
constexpr uint8_t kFrameFlagEsi = 1u << 3;      ///< GS_CAN_FLAG_ESI: FD error state indicator.

/// Bytes of a classic host frame: echo_id (4), can_id (4), can_dlc,
/// channel, flags, reserved (1 each), data (8).
constexpr size_t kHostFrameSize = 20;
/// Bytes of a classic host frame with GS_CAN_MODE_HW_TIMESTAMP: a
/// little-endian timestamp_us (4) follows the data (struct classic_can_ts).
constexpr size_t kHostFrameTimestampedSize = 24;

/// can_id flags and masks (include/uapi/linux/can.h).
constexpr uint32_t kCanIdExtendedFlag = 0x80000000; ///< CAN_EFF_FLAG: 29-bit identifier.
constexpr uint32_t kCanIdRemoteFlag = 0x40000000;   ///< CAN_RTR_FLAG: remote transmission request.
constexpr uint32_t kCanIdErrorFlag = 0x20000000;    ///< CAN_ERR_FLAG: an error frame, not a bus frame.
constexpr uint32_t kCanIdExtendedMask = 0x1FFFFFFF; ///< CAN_EFF_MASK.
constexpr uint32_t kCanIdStandardMask = 0x000007FF; ///< CAN_SFF_MASK.

// ---------------------------------------------------------------------------
// The structures, in host order. Their wire form is little-endian and packed.

/// struct gs_device_config (12 bytes): reserved1..3, icount, sw_version, hw_version.
struct DeviceConfig {
    static constexpr size_t kSize = 12;
    uint8_t icount = 0;        ///< The number of CAN channels minus one.
    uint32_t softwareVersion = 0;
    uint32_t hardwareVersion = 0;

    /// How many CAN channels the interface has.
    unsigned channels() const { return unsigned{icount} + 1; }
};

/// struct gs_device_bt_const (40 bytes): feature, fclk_can, tseg1_min,
/// tseg1_max, tseg2_min, tseg2_max, sjw_max, brp_min, brp_max, brp_inc.
/// tseg1 counts the propagation and phase 1 segments together, in time quanta.
struct BitTimingConst {
    static constexpr size_t kSize = 40;
    uint32_t feature = 0;
    uint32_t clockHz = 0;
    uint32_t tseg1Min = 0;
    uint32_t tseg1Max = 0;
    uint32_t tseg2Min = 0;
    uint32_t tseg2Max = 0;
    uint32_t sjwMax = 0;
    uint32_t brpMin = 0;
    uint32_t brpMax = 0;
    uint32_t brpIncrement = 0;
};

/// struct gs_device_bittiming (20 bytes): prop_seg, phase_seg1, phase_seg2, sjw, brp.
struct BitTiming {
    static constexpr size_t kSize = 20;
    uint32_t propSeg = 0;
    uint32_t phaseSeg1 = 0;
    uint32_t phaseSeg2 = 0;
    uint32_t sjw = 0;
    uint32_t brp = 0;

    friend bool operator==(const BitTiming& a, const BitTiming& b)
    {
        return a.propSeg == b.propSeg && a.phaseSeg1 == b.phaseSeg1 && a.phaseSeg2 == b.phaseSeg2 && a.sjw == b.sjw &&
               a.brp == b.brp;
    }
};

/// struct gs_device_mode (8 bytes): mode, flags.
struct DeviceMode {
    static constexpr size_t kSize = 8;
    uint32_t mode = kModeReset;
    uint32_t flags = kModeFlagNormal;
};

/// struct gs_host_frame, classic CAN, with the optional hardware timestamp.
struct HostFrame {
    uint32_t echoId = kEchoIdReceived;
    uint32_t canId = 0;   ///< Identifier with Linux's CAN_*_FLAG bits.
    uint8_t dlc = 0;
    uint8_t channel = 0;
    uint8_t flags = 0;
    uint8_t reserved = 0;
    uint8_t data[8] = {};
    bool hasTimestamp = false;
    uint32_t timestampUs = 0; ///< The device's microsecond clock, when hasTimestamp.
};

/// gs_host_config: the byte-order word HOST_FORMAT carries (4 bytes).
std::vector<uint8_t> encodeHostConfig();

/// DEVICE_CONFIG's answer; refused when shorter than 12 bytes.
Result<DeviceConfig> decodeDeviceConfig(const uint8_t* data, size_t size);
/// The 12 bytes a device answers DEVICE_CONFIG with (for fakes and emulators).
std::vector<uint8_t> encodeDeviceConfig(const DeviceConfig& config);

/// BT_CONST's answer; refused when shorter than 40 bytes, without a clock,
/// or with a minimum above its maximum. A brp_inc of 0 is read as 1.
Result<BitTimingConst> decodeBitTimingConst(const uint8_t* data, size_t size);
/// The 40 bytes a device answers BT_CONST with (for fakes and emulators).
std::vector<uint8_t> encodeBitTimingConst(const BitTimingConst& limits);

/// BITTIMING's 20 bytes.
std::vector<uint8_t> encodeBitTiming(const BitTiming& timing);
/// BITTIMING's data as a device reads it; refused when shorter than 20 bytes.
Result<BitTiming> decodeBitTiming(const uint8_t* data, size_t size);

/// MODE's 8 bytes.
std::vector<uint8_t> encodeDeviceMode(const DeviceMode& mode);
/// MODE's data as a device reads it; refused when shorter than 8 bytes.
Result<DeviceMode> decodeDeviceMode(const uint8_t* data, size_t size);

/// A host frame's bytes: 20, or 24 with its timestamp.
std::vector<uint8_t> encodeHostFrame(const HostFrame& frame);

/// One bulk IN transfer as a host frame. Refused: fewer than 20 bytes (24
/// when @p timestamps, the channel having been started with
/// GS_CAN_MODE_HW_TIMESTAMP), and a CAN FD frame, for which the channel was
/// not started. Longer transfers are accepted and the rest ignored: a
/// device may pad its packets (GS_CAN_MODE_PAD_PKTS_TO_MAX_PKT_SIZE).
Result<HostFrame> decodeHostFrame(const uint8_t* data, size_t size, bool timestamps);

/// The host frame that sends @p frame on @p channel with @p echoId.
HostFrame hostFrameFor(const can::CanFrame& frame, uint32_t echoId, uint8_t channel);

/// The CAN frame a host frame carries (not an error frame). Refused: a
/// data length code above 8 (DCOS, SocketCAN and slcan refuse 9..15 too),
/// a standard identifier with bits above 11, an error frame.
Result<can::CanFrame> canFrameOf(const HostFrame& frame);

/// What one IN transfer means to the host.
struct InTransfer {
    bool isEcho = false;   ///< The echo of a frame we sent: it is on the bus now.
    uint32_t echoId = 0;   ///< For an echo: the echo_id we gave the frame.
    uint8_t channel = 0;
    /// For a received frame: the frame, or the events of an error frame.
    /// For either: an Overrun event when the device set the overflow flag.
    std::vector<Received> received;
};

/// Decodes one bulk IN transfer of an interface with @p channels channels:
/// a received frame becomes a Frame, an error frame (CAN_ERR_FLAG) the
/// events its bytes report (linux/can/error.h, as decodeErrorFrame reads
/// them), the overflow flag an Overrun event; an echo is reported with its
/// id. Refused: what decodeHostFrame and canFrameOf refuse, and a channel
/// the interface does not have. Timestamps are left for the caller.
Result<InTransfer> decodeInTransfer(const uint8_t* data, size_t size, bool timestamps, unsigned channels);

// ---------------------------------------------------------------------------
// Bit timing.

/// The sample point CiA 301 (and CiA 601-3) recommends for every bit rate,
/// in tenths of a percent: 87.5 %.
constexpr uint32_t kSamplePointPermille = 875;
/// The largest difference between the wanted and the made bit rate we
/// accept, in parts per million (0.1 %): every error of the nominal rate is
/// taken from the oscillator tolerance that the bus's nodes share, so a
/// rate the clock cannot divide down to closely is refused, not approximated.
constexpr uint32_t kMaxBitRateErrorPpm = 1000;

/// The lowest bit rate we drive an adapter at, in bit/s: no CAN bus DCOS
/// meets runs slower, and the bound keeps the prescaler search short for
/// any clock a device may claim.
constexpr uint32_t kMinBitRate = 1'000;
/// Classic CAN's highest nominal bit rate (ISO 11898-1), in bit/s; a faster
/// rate is a mistake even when the device's clock could make it.
constexpr uint32_t kMaxBitRate = 1'000'000;

/// A bit timing chosen for a bit rate.
struct BitTimingChoice {
    BitTiming timing;
    uint32_t bitRate = 0;             ///< The rate it makes: clock / (brp * quanta).
    uint32_t quanta = 0;              ///< Time quanta per bit: 1 + tseg1 + tseg2.
    uint32_t samplePointPermille = 0; ///< (1 + tseg1) / quanta, in tenths of a percent.
};

/// The bit timing for @p bitRate within @p limits: the smallest rate error
/// (at most kMaxBitRateErrorPpm), then the sample point nearest 87.5 %, then
/// the most time quanta per bit (the smallest prescaler). tseg1 is split as
/// Linux's can_calc_bittiming splits it (prop_seg = tseg1 / 2, phase_seg1 the
/// rest); the synchronisation jump width is as wide as phase_seg1,
/// phase_seg2 and sjw_max allow, for the most oscillator tolerance.
/// Refused, with what was asked and what the device offers, when no
/// prescaler and segments make the rate.
Result<BitTimingChoice> computeBitTiming(uint32_t bitRate, const BitTimingConst& limits);

} // namespace hostcan::gsusb
