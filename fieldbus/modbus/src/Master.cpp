#include <modbus/Master.hpp>

namespace modbus {

namespace {

constexpr uint64_t kNoDeadline = ~static_cast<uint64_t>(0);

} // namespace

ModbusError MasterConfig::validate() const
{
    if (responseTimeoutNs == 0 || responseTimeoutNs > kMaxDelayNs || turnaroundDelayNs == 0
        || turnaroundDelayNs > kMaxDelayNs || retries > kMaxRetries) {
        return ModbusError::InvalidConfiguration;
    }
    return ModbusError::Ok;
}

ModbusResult<Master> Master::create(Transport& transport, const MasterConfig& config)
{
    const ModbusError error = config.validate();
    if (error != ModbusError::Ok) {
        return error;
    }
    Master master;
    master.transport_ = &transport;
    master.config_ = config;
    return master;
}

StationStep Master::submit(const Request& request, uint64_t nowNs)
{
    StationStep step;
    if (transport_ == nullptr) {
        step.rejected = ModbusError::NotExpected;
        return step;
    }
    if (state_ != State::Idle) {
        step.rejected = ModbusError::Busy;
        return step;
    }
    const ModbusResult<size_t> adu = transport_->encode(request.unit, request.pdu, request.length, adu_, sizeof adu_);
    if (!adu.ok()) {
        step.rejected = adu.error();
        return step;
    }
    request_ = request;
    aduLength_ = adu.value();
    attempts_ = 0;
    responseLength_ = 0;
    state_ = State::WaitingToSend;
    ++counters_.transactions;
    // The line may have gone idle since the last call; bring it up to date.
    transport_->poll(nowNs);
    return sendIfReady(step);
}

StationStep Master::onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs)
{
    if (transport_ == nullptr) {
        return {};
    }
    transport_->onBytes(bytes, count, nowNs);
    return handleFrames(StationStep{});
}

StationStep Master::poll(uint64_t nowNs)
{
    if (transport_ == nullptr) {
        return {};
    }
    transport_->poll(nowNs);
    StationStep step = handleFrames(StationStep{});
    if (state_ == State::WaitingReply && nowNs >= deadline_ && !transport_->receiving()) {
        ++counters_.timeouts;
        step = failAttempt(step, ModbusError::Timeout);
    }
    if (state_ == State::Turnaround && nowNs >= deadline_) {
        step = complete(step, ModbusError::Ok, ExceptionCode::None);
    }
    return sendIfReady(step);
}

StationStep Master::onTransmitDone(uint64_t nowNs)
{
    StationStep step;
    if (state_ != State::Transmitting) {
        step.rejected = ModbusError::NotExpected;
        return step;
    }
    transport_->onTransmitDone(nowNs);
    if (request_.isBroadcast()) {
        state_ = State::Turnaround;
        deadline_ = nowNs + config_.turnaroundDelayNs;
    } else {
        state_ = State::WaitingReply;
        deadline_ = nowNs + config_.responseTimeoutNs;
    }
    return step;
}

uint64_t Master::nextDeadlineNs() const
{
    if (transport_ == nullptr) {
        return kNoDeadline;
    }
    uint64_t next = transport_->nextDeadlineNs();
    if ((state_ == State::WaitingReply || state_ == State::Turnaround) && deadline_ < next) {
        next = deadline_;
    }
    return next;
}

StationStep Master::handleFrames(StationStep step)
{
    ReceivedFrame frame;
    while (transport_->takeFrame(frame)) {
        if (state_ != State::WaitingReply || frame.unit != request_.unit) {
            // [SL] 2.4.1: a reply from an unexpected slave leaves the
            // response time-out running.
            ++counters_.foreignFrames;
            continue;
        }
        ExceptionCode exception = ExceptionCode::None;
        const ModbusError error = checkResponse(request_, frame.pdu, frame.length, exception);
        if (error == ModbusError::Ok || error == ModbusError::ExceptionResponse) {
            for (size_t i = 0; i < frame.length; ++i) {
                response_[i] = frame.pdu[i];
            }
            responseLength_ = frame.length;
            ++counters_.responses;
            if (error == ModbusError::ExceptionResponse) {
                ++counters_.exceptions;
            }
            step = complete(step, error, exception);
        } else {
            ++counters_.invalidResponses;
            step = failAttempt(step, error);
        }
    }
    return step;
}

StationStep Master::failAttempt(StationStep step, ModbusError error)
{
    // attempts_ counts transmissions: the first and config_.retries more.
    if (attempts_ < 1 + config_.retries) {
        state_ = State::WaitingToSend;
        return step;
    }
    ++counters_.failures;
    return complete(step, error, ExceptionCode::None);
}

StationStep Master::sendIfReady(StationStep step)
{
    if (state_ == State::WaitingToSend && transport_->readyToSend()) {
        state_ = State::Transmitting;
        ++attempts_;
        ++counters_.transmissions;
        step.transmit = adu_;
        step.transmitLength = aduLength_;
    }
    return step;
}

StationStep Master::complete(StationStep step, ModbusError error, ExceptionCode exception)
{
    state_ = State::Idle;
    step.completed = true;
    step.error = error;
    step.exception = exception;
    return step;
}

} // namespace modbus
