#include <can/IsoTpRequestServer.hpp>

#include <can/IsoTpPci.hpp>
#include <can/MessageIdentifier.hpp>

namespace can {

namespace {

// The identifier's fields packed as MessageIdentifier::encode packs them,
// without make()'s refusal of source 255: a selected configuration node
// answers from it (docs/protocols/config.md, "Scanning").
uint32_t rawIdentifier(uint8_t priority, MessageType type, uint8_t destination, uint8_t source)
{
    return (static_cast<uint32_t>(priority) << MessageIdentifier::kPriorityShift) |
           (static_cast<uint32_t>(type) << MessageIdentifier::kTypeShift) |
           (static_cast<uint32_t>(destination) << MessageIdentifier::kDestinationShift) |
           (static_cast<uint32_t>(source) << MessageIdentifier::kSourceShift);
}

} // namespace

IsoTpConfig isoTpRequestConnection(MessageType type, uint8_t node, uint8_t host, uint8_t priority, bool hostSide,
                                   uint8_t nodeBlockSize)
{
    IsoTpConfig config;
    // The callers pass node numbers and priorities they checked, so a value
    // out of range here leaves identifier 0, which validate() accepts but no
    // DCOS frame uses.
    if (priority <= MessageIdentifier::kLowestPriority && host != MessageIdentifier::kBroadcast) {
        const uint32_t toNode = rawIdentifier(priority, type, node, host);
        const uint32_t toHost = rawIdentifier(priority, type, host, node);
        config.txId = hostSide ? toNode : toHost;
        config.rxId = hostSide ? toHost : toNode;
    }
    config.format = IdFormat::Extended;
    config.blockSize = hostSide ? 0 : nodeBlockSize;
    return config;
}

void IsoTpRequestServer::open(uint8_t address)
{
    if (open_ && address == address_) {
        return;
    }
    endConnection();
    address_ = address;
    open_ = true;
}

void IsoTpRequestServer::close()
{
    endConnection();
    open_ = false;
}

void IsoTpRequestServer::endConnection()
{
    if (busy()) {
        ++statistics_.aborted;
    }
    receiver_.abort();
    giveUpReply();
    connected_ = false;
}

void IsoTpRequestServer::giveUpReply()
{
    if (!sender_.idle()) {
        sender_.abort();
        handler_.replyEnded(false);
    }
}

void IsoTpRequestServer::connect(uint8_t host, uint8_t priority)
{
    if (connected_ && host == peer_ && priority == priority_) {
        return;
    }
    if (busy()) {
        ++statistics_.aborted;
    }
    giveUpReply();
    const IsoTpConfig config = isoTpRequestConnection(type_, address_, host, priority, false, blockSize_);
    // The configuration is valid by construction (two DCOS identifiers, the
    // defaults otherwise), so neither create() fails.
    receiver_ = IsoTpReceiver::create(config, request_, requestCapacity_).value();
    sender_ = IsoTpSender::create(config).value();
    peer_ = host;
    priority_ = priority;
    connected_ = true;
    ++statistics_.connections;
}

IsoTpRequestServer::Output IsoTpRequestServer::onFrame(const CanFrame& frame, uint64_t nowNs)
{
    const LinkResult<MessageIdentifier> identifier = MessageIdentifier::fromFrame(frame);
    if (!open_ || !identifier.ok() || identifier.value().type() != type_ ||
        identifier.value().destination() != address_) {
        ++statistics_.ignored;
        return {};
    }
    const LinkResult<PciType> type = IsoTpPci::typeOf(frame);
    if (!type.ok()) {
        ++statistics_.ignored;
        return {};
    }
    const bool beginsMessage = type.value() == PciType::SingleFrame || type.value() == PciType::FirstFrame;
    if (beginsMessage) {
        connect(identifier.value().source(), identifier.value().priority());
        if (!sender_.idle()) {
            // The host asks again before our reply went: it gave up on it.
            ++statistics_.aborted;
            giveUpReply();
        }
    }
    if (!connected_) {
        ++statistics_.ignored;
        return {};
    }
    if (type.value() == PciType::FlowControl) {
        const IsoTpStep step = sender_.onFrame(frame, nowNs);
        if (step.rejected != LinkError::Ok) {
            ++statistics_.ignored;
        }
        return afterSend(step);
    }
    const IsoTpStep step = receiver_.onFrame(frame, nowNs);
    if (step.rejected != LinkError::Ok && step.rejected != LinkError::BufferOverflow) {
        ++statistics_.ignored;
    }
    return afterReceive(step, nowNs);
}

IsoTpRequestServer::Output IsoTpRequestServer::afterReceive(const IsoTpStep& step, uint64_t nowNs)
{
    if (step.aborted != LinkError::Ok) {
        ++statistics_.aborted;
    }
    if (!step.completed) {
        Output output;
        output.transmit = step.transmit;
        output.frame = step.frame;
        return output;
    }
    ++statistics_.requests;
    const size_t length = handler_.handleRequest(request_, step.length, reply_, replyCapacity_, nowNs);
    if (length == 0) {
        return {};
    }
    return afterSend(sender_.start(reply_, length, nowNs));
}

IsoTpRequestServer::Output IsoTpRequestServer::afterSend(const IsoTpStep& step)
{
    if (step.transmit) {
        senderFrameOut_ = true;
    }
    if (step.completed) {
        ++statistics_.replies;
        handler_.replyEnded(true);
    }
    if (step.aborted != LinkError::Ok) {
        ++statistics_.aborted;
        handler_.replyEnded(false);
    }
    Output output;
    output.transmit = step.transmit;
    output.frame = step.frame;
    return output;
}

IsoTpRequestServer::Output IsoTpRequestServer::onTransmitConfirmed(uint64_t nowNs)
{
    if (!connected_) {
        return {};
    }
    if (sender_.idle()) {
        return {}; // A flow control of the receiver went: nothing waits for it.
    }
    senderFrameOut_ = false;
    return afterSend(sender_.onTransmitConfirmed(nowNs));
}

IsoTpRequestServer::Output IsoTpRequestServer::poll(uint64_t nowNs)
{
    if (!connected_) {
        return {};
    }
    const IsoTpStep received = receiver_.poll(nowNs);
    if (received.aborted != LinkError::Ok) {
        ++statistics_.aborted;
    }
    return afterSend(sender_.poll(nowNs));
}

uint64_t IsoTpRequestServer::nextDeadlineNs() const
{
    const uint64_t receiving = receiver_.nextDeadlineNs();
    const uint64_t sending = sender_.nextDeadlineNs();
    return receiving < sending ? receiving : sending;
}

} // namespace can
