#include <can/IsoTpSender.hpp>

namespace can {

IsoTpSender::IsoTpSender(const IsoTpConfig& config) : config_(config), configured_(true) {}

LinkResult<IsoTpSender> IsoTpSender::create(const IsoTpConfig& config)
{
    const LinkError error = config.validate();
    if (error != LinkError::Ok) {
        return error;
    }
    return IsoTpSender(config);
}

uint64_t IsoTpSender::after(uint64_t nowNs, uint64_t intervalNs)
{
    // Saturates instead of wrapping, so a deadline never lies in the past.
    return intervalNs > kNoDeadline - nowNs ? kNoDeadline : nowNs + intervalNs;
}

IsoTpStep IsoTpSender::start(const uint8_t* message, size_t length, uint64_t nowNs)
{
    IsoTpStep step;
    if (!configured_) {
        step.rejected = LinkError::InvalidConfiguration;
        return step;
    }
    step.aborted = expire(nowNs);
    if (state_ != State::Idle) {
        step.rejected = LinkError::Busy;
        return step;
    }
    if (length == 0 || length > IsoTpPci::kMaxMessageLength) {
        step.rejected = LinkError::InvalidMessageLength;
        return step;
    }
    if (message == nullptr) {
        step.rejected = LinkError::InvalidArgument;
        return step;
    }

    message_ = message;
    length_ = static_cast<uint16_t>(length);
    uint8_t bytes[CanFrame::kMaxDataLength];
    if (length_ <= IsoTpPci::kMaxSingleFrameData) {
        // SingleFrame N_PCI: type 0 and SF_DL in one byte, then the data.
        bytes[0] = IsoTpPci::pciByte(PciType::SingleFrame, static_cast<uint8_t>(length_));
        for (uint16_t i = 0; i < length_; ++i) {
            bytes[1 + i] = message_[i];
        }
        step.frame = IsoTpPci::makeFrame(config_.txId, config_.format, bytes, static_cast<uint8_t>(1 + length_),
                                         config_.padding);
        pending_ = Pending::Single;
        offset_ = length_;
    } else {
        // FirstFrame N_PCI: type 1 and the 12-bit FF_DL in two bytes, then
        // the first six bytes. A first frame is always 8 bytes long.
        bytes[0] = IsoTpPci::pciByte(PciType::FirstFrame, static_cast<uint8_t>(length_ >> 8));
        bytes[1] = static_cast<uint8_t>(length_ & 0xFF);
        for (uint8_t i = 0; i < IsoTpPci::kFirstFrameData; ++i) {
            bytes[IsoTpPci::kFirstFramePciLength + i] = message_[i];
        }
        step.frame = IsoTpPci::makeFrame(config_.txId, config_.format, bytes, CanFrame::kMaxDataLength,
                                         config_.padding);
        pending_ = Pending::First;
        offset_ = IsoTpPci::kFirstFrameData;
        // The first frame is segment 0 (ISO 15765-2 9.6.4.3); the first CF is 1.
        sequence_ = 1;
        blockSize_ = 0;
        blockCount_ = 0;
        waits_ = 0;
        flowParametersKnown_ = false;
        separationNs_ = 0;
    }
    step.transmit = true;
    state_ = State::AwaitingConfirmation;
    deadline_ = after(nowNs, config_.timeoutAsNs);
    return step;
}

IsoTpStep IsoTpSender::onTransmitConfirmed(uint64_t nowNs)
{
    IsoTpStep step;
    step.aborted = expire(nowNs);
    if (state_ != State::AwaitingConfirmation) {
        step.rejected = LinkError::NotExpected;
        return step;
    }
    switch (pending_) {
    case Pending::Single:
        step.completed = true;
        step.length = length_;
        finish();
        return step;
    case Pending::First:
        state_ = State::AwaitingFlowControl;
        deadline_ = after(nowNs, config_.timeoutBsNs);
        return step;
    case Pending::Consecutive:
        break;
    }
    if (offset_ == length_) {
        step.completed = true;
        step.length = length_;
        finish();
    } else if (blockSize_ != 0 && blockCount_ == blockSize_) {
        state_ = State::AwaitingFlowControl;
        deadline_ = after(nowNs, config_.timeoutBsNs);
    } else if (separationNs_ == 0) {
        emitConsecutive(step, nowNs);
    } else {
        state_ = State::Separating;
        deadline_ = after(nowNs, separationNs_);
    }
    return step;
}

IsoTpStep IsoTpSender::onFrame(const CanFrame& frame, uint64_t nowNs)
{
    IsoTpStep step;
    step.aborted = expire(nowNs);
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
    // Data frames on rxId belong to this end's receiver.
    if (type.value() != PciType::FlowControl) {
        step.rejected = LinkError::NotExpected;
        return step;
    }
    if (frame.length() < IsoTpPci::kFlowControlLength
        || (config_.requirePaddedFrames && frame.length() != CanFrame::kMaxDataLength)) {
        step.rejected = LinkError::ShortFrame;
        return step;
    }
    // "Unexpected arrival of N_PDU": a flow control the sender is not waiting for is ignored.
    if (state_ != State::AwaitingFlowControl) {
        step.rejected = LinkError::NotExpected;
        return step;
    }

    switch (static_cast<FlowStatus>(frame.byte(0) & IsoTpPci::kLowNibble)) {
    case FlowStatus::ContinueToSend:
        if (!flowParametersKnown_) {
            blockSize_ = frame.byte(1);
            separationNs_ = IsoTpPci::separationTimeNs(frame.byte(2));
            flowParametersKnown_ = true;
        }
        blockCount_ = 0;
        waits_ = 0;
        emitConsecutive(step, nowNs);
        return step;
    case FlowStatus::Wait:
        if (waits_ >= config_.maxWaitFrames) {
            step.aborted = LinkError::WaitLimitExceeded;
            finish();
            return step;
        }
        ++waits_;
        deadline_ = after(nowNs, config_.timeoutBsNs);
        return step;
    case FlowStatus::Overflow:
        // Overflow answers the first frame; later in a message it is a
        // flow status the standard does not allow there.
        step.aborted = flowParametersKnown_ ? LinkError::InvalidFlowStatus : LinkError::BufferOverflow;
        finish();
        return step;
    }
    step.aborted = LinkError::InvalidFlowStatus;
    finish();
    return step;
}

IsoTpStep IsoTpSender::poll(uint64_t nowNs)
{
    IsoTpStep step;
    step.aborted = expire(nowNs);
    if (state_ == State::Separating && nowNs >= deadline_) {
        emitConsecutive(step, nowNs);
    }
    return step;
}

uint64_t IsoTpSender::nextDeadlineNs() const
{
    return state_ == State::Idle ? kNoDeadline : deadline_;
}

void IsoTpSender::abort()
{
    finish();
}

LinkError IsoTpSender::expire(uint64_t nowNs)
{
    if (nowNs < deadline_) {
        return LinkError::Ok;
    }
    LinkError error = LinkError::Ok;
    if (state_ == State::AwaitingConfirmation) {
        error = LinkError::TimeoutA;
    } else if (state_ == State::AwaitingFlowControl) {
        error = LinkError::TimeoutBs;
    } else {
        return LinkError::Ok;
    }
    finish();
    return error;
}

void IsoTpSender::emitConsecutive(IsoTpStep& step, uint64_t nowNs)
{
    // ConsecutiveFrame N_PCI: type 2 and the sequence number, then up to 7 bytes.
    const uint16_t remaining = static_cast<uint16_t>(length_ - offset_);
    const uint8_t count =
        remaining < IsoTpPci::kConsecutiveFrameData ? static_cast<uint8_t>(remaining) : IsoTpPci::kConsecutiveFrameData;
    uint8_t bytes[CanFrame::kMaxDataLength];
    bytes[0] = IsoTpPci::pciByte(PciType::ConsecutiveFrame, sequence_);
    for (uint8_t i = 0; i < count; ++i) {
        bytes[1 + i] = message_[offset_ + i];
    }
    step.frame = IsoTpPci::makeFrame(config_.txId, config_.format, bytes, static_cast<uint8_t>(1 + count),
                                     config_.padding);
    step.transmit = true;
    offset_ = static_cast<uint16_t>(offset_ + count);
    sequence_ = static_cast<uint8_t>((sequence_ + 1) % IsoTpPci::kSequenceModulus);
    ++blockCount_;
    pending_ = Pending::Consecutive;
    state_ = State::AwaitingConfirmation;
    deadline_ = after(nowNs, config_.timeoutAsNs);
}

void IsoTpSender::finish()
{
    state_ = State::Idle;
    message_ = nullptr;
    deadline_ = kNoDeadline;
}

} // namespace can
