#include <flash/CanFlashServer.hpp>

#include <can/IsoTpPci.hpp>
#include <can/MessageIdentifier.hpp>

namespace flash {

can::IsoTpConfig canFlashConnection(uint8_t node, uint8_t host, uint8_t priority, bool hostSide)
{
    const uint8_t from = hostSide ? host : node;
    const uint8_t to = hostSide ? node : host;
    can::IsoTpConfig config;
    // make() refuses only values out of range; the callers pass node numbers
    // and priorities they checked, so an error here leaves identifier 0,
    // which validate() accepts but no DCOS frame uses.
    const can::LinkResult<can::MessageIdentifier> tx = can::MessageIdentifier::make(priority, can::MessageType::Flashing, to, from);
    const can::LinkResult<can::MessageIdentifier> rx = can::MessageIdentifier::make(priority, can::MessageType::Flashing, from, to);
    config.txId = tx.ok() ? tx.value().encode() : 0;
    config.rxId = rx.ok() ? rx.value().encode() : 0;
    config.format = can::IdFormat::Extended;
    config.blockSize = hostSide ? 0 : kCanNodeBlockSize;
    return config;
}

void CanFlashServer::setOwnNode(uint8_t ownNode)
{
    if (ownNode == ownNode_) {
        return;
    }
    if (busy()) {
        ++statistics_.aborted;
    }
    receiver_.abort();
    sender_.abort();
    connected_ = false;
    ownNode_ = ownNode;
}

void CanFlashServer::connect(uint8_t host, uint8_t priority)
{
    if (connected_ && host == peer_ && priority == priority_) {
        return;
    }
    if (busy()) {
        ++statistics_.aborted;
    }
    const can::IsoTpConfig config = canFlashConnection(ownNode_, host, priority, false);
    // The configuration is valid by construction (two DCOS identifiers,
    // the defaults otherwise), so neither create() fails.
    receiver_ = can::IsoTpReceiver::create(config, request_, sizeof request_).value();
    sender_ = can::IsoTpSender::create(config).value();
    peer_ = host;
    priority_ = priority;
    connected_ = true;
    ++statistics_.connections;
}

CanFlashServer::Output CanFlashServer::onFrame(const can::CanFrame& frame, uint64_t nowNs)
{
    const can::LinkResult<can::MessageIdentifier> identifier = can::MessageIdentifier::fromFrame(frame);
    if (!identifier.ok() || identifier.value().type() != can::MessageType::Flashing ||
        identifier.value().destination() != ownNode_) {
        ++statistics_.ignored;
        return {};
    }
    const can::LinkResult<can::PciType> type = can::IsoTpPci::typeOf(frame);
    if (!type.ok()) {
        ++statistics_.ignored;
        return {};
    }
    const bool beginsMessage = type.value() == can::PciType::SingleFrame || type.value() == can::PciType::FirstFrame;
    if (beginsMessage) {
        connect(identifier.value().source(), identifier.value().priority());
        if (!sender_.idle()) {
            // The host asks again before our reply went: it gave up on it.
            sender_.abort();
            ++statistics_.aborted;
            if (replyingToRestart_) {
                restartDue_ = true;
            }
        }
    }
    if (!connected_) {
        ++statistics_.ignored;
        return {};
    }
    if (type.value() == can::PciType::FlowControl) {
        const can::IsoTpStep step = sender_.onFrame(frame, nowNs);
        if (step.rejected != can::LinkError::Ok) {
            ++statistics_.ignored;
        }
        return afterSend(step);
    }
    const can::IsoTpStep step = receiver_.onFrame(frame, nowNs);
    if (step.rejected != can::LinkError::Ok && step.rejected != can::LinkError::BufferOverflow) {
        ++statistics_.ignored;
    }
    return afterReceive(step, nowNs);
}

CanFlashServer::Output CanFlashServer::afterReceive(const can::IsoTpStep& step, uint64_t nowNs)
{
    if (step.aborted != can::LinkError::Ok) {
        ++statistics_.aborted;
    }
    if (!step.completed) {
        Output output;
        output.transmit = step.transmit;
        output.frame = step.frame;
        return output;
    }
    ++statistics_.requests;
    const size_t length = session_.handle(request_, step.length, reply_, sizeof reply_);
    RestartTarget target{};
    replyingToRestart_ = session_.restartRequested(target);
    if (length == 0) {
        return {};
    }
    return afterSend(sender_.start(reply_, length, nowNs));
}

CanFlashServer::Output CanFlashServer::afterSend(const can::IsoTpStep& step)
{
    if (step.completed) {
        ++statistics_.replies;
    }
    if (step.aborted != can::LinkError::Ok) {
        ++statistics_.aborted;
    }
    if ((step.completed || step.aborted != can::LinkError::Ok) && replyingToRestart_) {
        restartDue_ = true;
    }
    Output output;
    output.transmit = step.transmit;
    output.frame = step.frame;
    return output;
}

CanFlashServer::Output CanFlashServer::onTransmitConfirmed(uint64_t nowNs)
{
    if (!connected_) {
        return {};
    }
    if (sender_.idle()) {
        return {}; // A flow control of the receiver went: nothing waits for it.
    }
    return afterSend(sender_.onTransmitConfirmed(nowNs));
}

CanFlashServer::Output CanFlashServer::poll(uint64_t nowNs)
{
    if (!connected_) {
        return {};
    }
    const can::IsoTpStep received = receiver_.poll(nowNs);
    if (received.aborted != can::LinkError::Ok) {
        ++statistics_.aborted;
    }
    return afterSend(sender_.poll(nowNs));
}

uint64_t CanFlashServer::nextDeadlineNs() const
{
    const uint64_t receiving = receiver_.nextDeadlineNs();
    const uint64_t sending = sender_.nextDeadlineNs();
    return receiving < sending ? receiving : sending;
}

bool CanFlashServer::restartDue(RestartTarget& target) const
{
    return restartDue_ && session_.restartRequested(target);
}

} // namespace flash
