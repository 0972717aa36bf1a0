#include <can/IsoTpReceiver.hpp>

namespace can {

namespace {

// Byte positions of the 32-bit FF_DL that follows an FF_DL escape of 0.
constexpr uint8_t kEscapedLengthFirstByte = 2;

} // namespace

IsoTpReceiver::IsoTpReceiver(const IsoTpConfig& config, uint8_t* buffer, uint16_t capacity, uint8_t stMin)
    : config_(config), buffer_(buffer), capacity_(capacity), stMin_(stMin)
{
}

LinkResult<IsoTpReceiver> IsoTpReceiver::create(const IsoTpConfig& config, uint8_t* buffer, size_t capacity)
{
    const LinkError error = config.validate();
    if (error != LinkError::Ok) {
        return error;
    }
    if (buffer == nullptr || capacity == 0) {
        return LinkError::InvalidArgument;
    }
    const uint16_t usable =
        capacity > IsoTpPci::kMaxMessageLength ? IsoTpPci::kMaxMessageLength : static_cast<uint16_t>(capacity);
    return IsoTpReceiver(config, buffer, usable, IsoTpPci::encodeSeparationTime(config.separationTimeNs).value());
}

uint64_t IsoTpReceiver::after(uint64_t nowNs, uint64_t intervalNs)
{
    return intervalNs > kNoDeadline - nowNs ? kNoDeadline : nowNs + intervalNs;
}

IsoTpStep IsoTpReceiver::onFrame(const CanFrame& frame, uint64_t nowNs)
{
    IsoTpStep step;
    step.aborted = expire(nowNs);
    if (buffer_ == nullptr) {
        step.rejected = LinkError::InvalidConfiguration;
        return step;
    }
    if (frame.id() != config_.rxId || frame.format() != config_.format) {
        step.rejected = LinkError::WrongIdentifier;
        return step;
    }
    if (frame.isRemote()) {
        step.rejected = LinkError::UnexpectedRemoteFrame;
        return step;
    }
    const LinkResult<PciType> type = IsoTpPci::typeOf(frame);
    if (!type.ok()) {
        step.rejected = type.error();
        return step;
    }
    if (config_.requirePaddedFrames && frame.length() != CanFrame::kMaxDataLength) {
        step.rejected = LinkError::ShortFrame;
        return step;
    }
    switch (type.value()) {
    case PciType::SingleFrame:
        takeSingleFrame(frame, step);
        break;
    case PciType::FirstFrame:
        takeFirstFrame(frame, step, nowNs);
        break;
    case PciType::ConsecutiveFrame:
        takeConsecutiveFrame(frame, step, nowNs);
        break;
    case PciType::FlowControl:
        // Flow control paces this end's sender, not its receiver.
        step.rejected = LinkError::NotExpected;
        break;
    }
    return step;
}

void IsoTpReceiver::takeSingleFrame(const CanFrame& frame, IsoTpStep& step)
{
    // "SF_DL error handling": 0, more than 7, or more than the frame carries is ignored.
    const uint8_t length = frame.byte(0) & IsoTpPci::kLowNibble;
    if (length == 0 || length > IsoTpPci::kMaxSingleFrameData || length > frame.length() - 1) {
        step.rejected = LinkError::InvalidSingleFrameLength;
        return;
    }
    if (receiving_) {
        step.aborted = LinkError::UnexpectedPdu;
        receiving_ = false;
    }
    if (length > capacity_) {
        step.rejected = LinkError::BufferOverflow;
        return;
    }
    for (uint8_t i = 0; i < length; ++i) {
        buffer_[i] = frame.byte(1 + i);
    }
    step.completed = true;
    step.length = length;
}

void IsoTpReceiver::takeFirstFrame(const CanFrame& frame, IsoTpStep& step, uint64_t nowNs)
{
    // A first frame fills the whole classic CAN frame: its data length is the
    // sender's TX_DL, 8, which Linux's can-isotp also insists on.
    if (frame.length() != CanFrame::kMaxDataLength) {
        step.rejected = LinkError::InvalidFirstFrame;
        return;
    }
    const uint16_t length = static_cast<uint16_t>(((frame.byte(0) & IsoTpPci::kLowNibble) << 8) | frame.byte(1));
    bool escaped = false;
    if (length == 0) {
        // The escape of ISO 15765-2:2016: a 32-bit FF_DL follows. One that
        // would have fitted 12 bits is ignored ("FF_DL error handling"); a
        // larger one is valid but exceeds any DCOS buffer.
        uint32_t escapedLength = 0;
        for (uint8_t i = 0; i < 4; ++i) {
            escapedLength = (escapedLength << 8) | frame.byte(kEscapedLengthFirstByte + i);
        }
        if (escapedLength <= IsoTpPci::kMaxMessageLength) {
            step.rejected = LinkError::InvalidFirstFrame;
            return;
        }
        escaped = true;
    } else if (length < IsoTpPci::kMinSegmentedLength) {
        // "FF_DL error handling": a message that fits a single frame is ignored.
        step.rejected = LinkError::InvalidFirstFrame;
        return;
    }
    if (receiving_) {
        step.aborted = LinkError::UnexpectedPdu;
        receiving_ = false;
    }
    if (escaped || length > capacity_) {
        step.transmit = true;
        step.frame = flowControl(FlowStatus::Overflow);
        step.rejected = LinkError::BufferOverflow;
        return;
    }
    for (uint8_t i = 0; i < IsoTpPci::kFirstFrameData; ++i) {
        buffer_[i] = frame.byte(IsoTpPci::kFirstFramePciLength + i);
    }
    expected_ = length;
    received_ = IsoTpPci::kFirstFrameData;
    sequence_ = 1;
    blockCount_ = 0;
    receiving_ = true;
    deadline_ = after(nowNs, config_.timeoutCrNs);
    step.transmit = true;
    step.frame = flowControl(FlowStatus::ContinueToSend);
}

void IsoTpReceiver::takeConsecutiveFrame(const CanFrame& frame, IsoTpStep& step, uint64_t nowNs)
{
    if (!receiving_) {
        step.rejected = LinkError::NotExpected;
        return;
    }
    const uint16_t remaining = static_cast<uint16_t>(expected_ - received_);
    const uint8_t count =
        remaining < IsoTpPci::kConsecutiveFrameData ? static_cast<uint8_t>(remaining) : IsoTpPci::kConsecutiveFrameData;
    // Only the last consecutive frame may be shorter than 8 bytes, and no
    // frame may be shorter than the bytes it has to carry.
    if (frame.length() - 1 < count) {
        step.rejected = LinkError::ShortFrame;
        return;
    }
    if ((frame.byte(0) & IsoTpPci::kLowNibble) != sequence_) {
        step.aborted = LinkError::WrongSequenceNumber;
        receiving_ = false;
        return;
    }
    for (uint8_t i = 0; i < count; ++i) {
        buffer_[received_ + i] = frame.byte(1 + i);
    }
    received_ = static_cast<uint16_t>(received_ + count);
    sequence_ = static_cast<uint8_t>((sequence_ + 1) % IsoTpPci::kSequenceModulus);
    if (received_ == expected_) {
        receiving_ = false;
        step.completed = true;
        step.length = expected_;
        return;
    }
    ++blockCount_;
    if (config_.blockSize != 0 && blockCount_ == config_.blockSize) {
        blockCount_ = 0;
        step.transmit = true;
        step.frame = flowControl(FlowStatus::ContinueToSend);
    }
    deadline_ = after(nowNs, config_.timeoutCrNs);
}

IsoTpStep IsoTpReceiver::poll(uint64_t nowNs)
{
    IsoTpStep step;
    step.aborted = expire(nowNs);
    return step;
}

LinkError IsoTpReceiver::expire(uint64_t nowNs)
{
    if (!receiving_ || nowNs < deadline_) {
        return LinkError::Ok;
    }
    receiving_ = false;
    return LinkError::TimeoutCr;
}

CanFrame IsoTpReceiver::flowControl(FlowStatus status) const
{
    return IsoTpPci::makeFlowControl(config_.txId, config_.format, status, config_.blockSize, stMin_,
                                     config_.padding);
}

} // namespace can
