// The monitoring stream's frames (MonitorFrame.hpp).
#include <sei/MonitorFrame.hpp>

namespace sei {

namespace {

uint16_t readU16(const uint8_t* bytes) { return static_cast<uint16_t>(bytes[0] | (bytes[1] << 8)); }

void writeU16(uint8_t* bytes, uint16_t value)
{
    bytes[0] = static_cast<uint8_t>(value);
    bytes[1] = static_cast<uint8_t>(value >> 8);
}

uint32_t readU32(const uint8_t* bytes)
{
    return static_cast<uint32_t>(bytes[0]) | (static_cast<uint32_t>(bytes[1]) << 8) |
           (static_cast<uint32_t>(bytes[2]) << 16) | (static_cast<uint32_t>(bytes[3]) << 24);
}

} // namespace

size_t MonitorFrame::encode(uint8_t (&out)[kMonitorFrameMax]) const
{
    out[0] = static_cast<uint8_t>(kind);
    switch (kind) {
    case MonitorFrameKind::Sample: {
        if (channel >= kSeiMaxMonitorChannels) {
            return 0;
        }
        out[1] = channel;
        writeU16(out + 2, timeMs);
        const uint32_t bits = static_cast<uint32_t>(value);
        for (size_t i = 0; i < 4; ++i) {
            out[4 + i] = static_cast<uint8_t>(bits >> (8 * i));
        }
        return kMonitorSampleSize;
    }
    case MonitorFrameKind::Log:
        if (textLength == 0 || textLength > kMonitorLogText) {
            return 0;
        }
        out[1] = sequence;
        for (size_t i = 0; i < textLength; ++i) {
            out[2 + i] = text[i];
        }
        return 2 + textLength;
    case MonitorFrameKind::Lost:
        if (lostBytes == 0) {
            return 0;
        }
        writeU16(out + 1, lostBytes);
        return kMonitorLostSize;
    case MonitorFrameKind::End:
        if (reason == static_cast<MonitorEndReason>(0) ||
            static_cast<uint8_t>(reason) > kMonitorLastEndReason) {
            return 0;
        }
        out[1] = static_cast<uint8_t>(reason);
        return kMonitorEndSize;
    }
    return 0;
}

bool MonitorFrame::decode(const uint8_t* data, size_t length, MonitorFrame& out)
{
    if (data == nullptr || length == 0 || length > kMonitorFrameMax) {
        return false;
    }
    MonitorFrame frame;
    switch (data[0]) {
    case static_cast<uint8_t>(MonitorFrameKind::Sample):
        if (length != kMonitorSampleSize || data[1] >= kSeiMaxMonitorChannels) {
            return false;
        }
        frame.kind = MonitorFrameKind::Sample;
        frame.channel = data[1];
        frame.timeMs = readU16(data + 2);
        frame.value = static_cast<int32_t>(readU32(data + 4));
        break;
    case static_cast<uint8_t>(MonitorFrameKind::Log):
        if (length < 3) {
            return false;
        }
        frame.kind = MonitorFrameKind::Log;
        frame.sequence = data[1];
        frame.textLength = static_cast<uint8_t>(length - 2);
        for (size_t i = 0; i < frame.textLength; ++i) {
            frame.text[i] = data[2 + i];
        }
        break;
    case static_cast<uint8_t>(MonitorFrameKind::Lost):
        if (length != kMonitorLostSize || readU16(data + 1) == 0) {
            return false;
        }
        frame.kind = MonitorFrameKind::Lost;
        frame.lostBytes = readU16(data + 1);
        break;
    case static_cast<uint8_t>(MonitorFrameKind::End):
        if (length != kMonitorEndSize || data[1] == 0 || data[1] > kMonitorLastEndReason) {
            return false;
        }
        frame.kind = MonitorFrameKind::End;
        frame.reason = static_cast<MonitorEndReason>(data[1]);
        break;
    default:
        return false;
    }
    out = frame;
    return true;
}

int32_t monitorSampleValue(const uint8_t (&page)[kSeiPageSize], uint8_t offset, SeiSampleFormat format)
{
    if (format > static_cast<SeiSampleFormat>(kSeiLastSampleFormat) ||
        static_cast<size_t>(offset) + seiSampleSize(format) > kSeiPageSize) {
        return 0;
    }
    const uint8_t* field = page + offset;
    switch (format) {
    case SeiSampleFormat::U8: return field[0];
    case SeiSampleFormat::I8: return static_cast<int8_t>(field[0]);
    case SeiSampleFormat::U16: return readU16(field);
    case SeiSampleFormat::I16: return static_cast<int16_t>(readU16(field));
    case SeiSampleFormat::U32:
    case SeiSampleFormat::I32: return static_cast<int32_t>(readU32(field));
    }
    return 0;
}

int64_t monitorSampleMeaning(int32_t value, SeiSampleFormat format)
{
    return format == SeiSampleFormat::U32 ? static_cast<int64_t>(static_cast<uint32_t>(value))
                                          : static_cast<int64_t>(value);
}

} // namespace sei
