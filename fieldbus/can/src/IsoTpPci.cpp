#include <can/IsoTpPci.hpp>

namespace can {

LinkResult<PciType> IsoTpPci::typeOf(const CanFrame& frame)
{
    if (frame.length() == 0) {
        return LinkError::ShortFrame;
    }
    const uint8_t type = frame.byte(0) >> kTypeShift;
    if (type > static_cast<uint8_t>(PciType::FlowControl)) {
        return LinkError::ReservedPciType;
    }
    return static_cast<PciType>(type);
}

CanFrame IsoTpPci::makeFrame(uint32_t id, IdFormat format, const uint8_t* bytes, uint8_t length,
                             const IsoTpPadding& padding)
{
    uint8_t data[CanFrame::kMaxDataLength];
    uint8_t used = 0;
    for (; used < length && used < CanFrame::kMaxDataLength; ++used) {
        data[used] = bytes[used];
    }
    if (padding.enabled) {
        for (uint8_t i = used; i < CanFrame::kMaxDataLength; ++i) {
            data[i] = padding.value;
        }
        used = CanFrame::kMaxDataLength;
    }
    // The callers pass identifiers checked by IsoTpConfig::validate() and at
    // most 8 bytes, so the frame is always valid; a default frame would only
    // come back from a programming error, and then carries no data.
    const LinkResult<CanFrame> frame = CanFrame::makeData(id, format, data, used);
    return frame.ok() ? frame.value() : CanFrame();
}

CanFrame IsoTpPci::makeFlowControl(uint32_t id, IdFormat format, FlowStatus status, uint8_t blockSize,
                                   uint8_t stMin, const IsoTpPadding& padding)
{
    const uint8_t bytes[kFlowControlLength] = {
        pciByte(PciType::FlowControl, static_cast<uint8_t>(status)),
        blockSize,
        stMin,
    };
    return makeFrame(id, format, bytes, kFlowControlLength, padding);
}

} // namespace can
