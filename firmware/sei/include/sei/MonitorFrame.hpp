// The frames of the monitoring stream (docs/protocols/monitor.md): what a
// node sends, unacknowledged, to the host whose Monitor command asked for
// it, one classic CAN frame each in the DCOS message type Monitoring
// (0x41). Every number is little-endian. Pure code, the same in the node,
// which encodes, and in the host tool, which decodes; the decoder refuses
// every frame that is not exactly one of the four layouts, since a host
// that guessed at a malformed frame would plot a value nobody sent.
#pragma once

#include <sei/SeiMessage.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

/// The first byte of every stream frame.
enum class MonitorFrameKind : uint8_t {
    Sample = 0x01, ///< [kind][channel][time ms, u16][value, i32]
    Log = 0x02,    ///< [kind][sequence][1..6 bytes of console text]
    Lost = 0x03,   ///< [kind][bytes, u16]: console bytes the node's ring dropped
    End = 0x04,    ///< [kind][reason]: the stream ended
};

/// Why a stream ended (an End frame's second byte).
enum class MonitorEndReason : uint8_t {
    LeaseExpired = 1, ///< The host did not renew it in time.
    Stopped = 2,      ///< A Monitor with lease 0 stopped it.
    Replaced = 3,     ///< Another host's Monitor took the stream over.
};
constexpr uint8_t kMonitorLastEndReason = static_cast<uint8_t>(MonitorEndReason::Replaced);

/// A classic CAN frame's data.
constexpr size_t kMonitorFrameMax = 8;
/// The console bytes one Log frame carries at most.
constexpr size_t kMonitorLogText = 6;
constexpr size_t kMonitorSampleSize = 8;
constexpr size_t kMonitorLostSize = 3;
constexpr size_t kMonitorEndSize = 2;

/// One frame of the stream; the fields its kind does not use are ignored.
struct MonitorFrame {
    MonitorFrameKind kind = MonitorFrameKind::Sample;
    /// Sample: the channel's index in the Monitor request (0..7).
    uint8_t channel = 0;
    /// Sample: the node's uptime in milliseconds, modulo 65536.
    uint16_t timeMs = 0;
    /// Sample: the field, sign- or zero-extended to 32 bits (a U32 above
    /// 2^31 reads as negative here; the host knows the channel's format).
    int32_t value = 0;
    /// Log: counts Log frames modulo 256 from the stream's start.
    uint8_t sequence = 0;
    /// Log: 1..6 bytes.
    uint8_t textLength = 0;
    uint8_t text[kMonitorLogText] = {};
    /// Lost: console bytes dropped (1..65535).
    uint16_t lostBytes = 0;
    /// End.
    MonitorEndReason reason = MonitorEndReason::LeaseExpired;

    /// Writes the frame's data into @p out; its length, or 0 when a field
    /// is out of its range (a channel above 7, a Log without text or with
    /// more than six bytes, a Lost of nothing, an unknown reason).
    size_t encode(uint8_t (&out)[kMonitorFrameMax]) const;
    /// Reads the @p length bytes at @p data; false unless they are exactly
    /// one of the four layouts with every field in its range.
    static bool decode(const uint8_t* data, size_t length, MonitorFrame& out);
};

/// The field of @p format at @p offset in a publication's page, sign- or
/// zero-extended as the format says; 0 when the field does not fit the page
/// (the Monitor request's decoder refuses such a channel already).
int32_t monitorSampleValue(const uint8_t (&page)[kSeiPageSize], uint8_t offset, SeiSampleFormat format);

/// The value a sample of @p format carries, as the channel's field meant
/// it: a U32's bits as unsigned, every other format as the signed value.
int64_t monitorSampleMeaning(int32_t value, SeiSampleFormat format);

} // namespace sei
