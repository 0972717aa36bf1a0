#include <sei/CanSeiServer.hpp>

#include <can/IsoTpPci.hpp>
#include <can/MessageIdentifier.hpp>

namespace sei {

namespace {

using can::MessageIdentifier;

static_assert(SeiServer::kMaxNodeId == MessageIdentifier::kMaxNodeNumber,
              "SetNodeId takes exactly the node ids a CAN node number can carry");

// The scanning commands and ActivateBitRate: every node on the bus takes
// them from the broadcast address, selected or not.
bool isScanCommand(uint8_t code)
{
    return isSeiCommand(code) && seiCommandIsBroadcast(static_cast<SeiCommand>(code));
}

// The length of the message a single frame carries, or 0 when the frame is
// not a single frame ISO-TP would take.
uint8_t singleFrameLength(const can::CanFrame& frame)
{
    const can::LinkResult<can::PciType> type = can::IsoTpPci::typeOf(frame);
    if (!type.ok() || type.value() != can::PciType::SingleFrame) {
        return 0;
    }
    const uint8_t length = frame.data()[0] & can::IsoTpPci::kLowNibble;
    return length <= can::IsoTpPci::kMaxSingleFrameData && length < frame.length() ? length : 0;
}

} // namespace

can::IsoTpConfig canSeiConnection(uint8_t node, uint8_t host, uint8_t priority, bool hostSide)
{
    return can::isoTpRequestConnection(can::MessageType::Configuration, node, host, priority, hostSide,
                                       kCanSeiNodeBlockSize);
}

CanSeiServer::Endpoint::Endpoint(SeiServer& server)
    : server(server), connection(*this, can::MessageType::Configuration, kCanSeiNodeBlockSize, request, sizeof request,
                                 reply, sizeof reply)
{
}

size_t CanSeiServer::Endpoint::handleRequest(const uint8_t* bytes, size_t length, uint8_t* out, size_t capacity,
                                             uint64_t nowNs)
{
    const size_t replyLength = server.handle(bytes, length, out, capacity, nowNs);
    // Only the Ok answer to a Restart, on this connection, ends in a restart.
    replyingToRestart = replyLength >= kSeiReplyHeaderSize &&
                        out[0] == (static_cast<uint8_t>(SeiCommand::Restart) | kSeiReplyBit) &&
                        out[1] == static_cast<uint8_t>(SeiStatus::Ok);
    return replyLength;
}

void CanSeiServer::Endpoint::replyEnded(bool)
{
    if (replyingToRestart) {
        restartDue = true;
    }
}

CanSeiServer::CanSeiServer(SeiServer& server, uint8_t ownNode) : server_(server), own_(server), broadcast_(server)
{
    setOwnNode(ownNode);
    followSelection();
}

void CanSeiServer::setOwnNode(uint8_t ownNode)
{
    if (ownNode == MessageIdentifier::kBroadcast) {
        own_.connection.close();
    } else {
        own_.connection.open(ownNode);
    }
}

// The server's selection may also change through another carrier of the
// protocol, so every input looks at it before the connections do.
void CanSeiServer::followSelection()
{
    if (server_.selected()) {
        broadcast_.connection.open(MessageIdentifier::kBroadcast);
    } else if (broadcast_.connection.isOpen()) {
        broadcast_.connection.close();
    }
}

CanSeiServer::Output CanSeiServer::track(Endpoint& endpoint, const Output& output)
{
    if (output.transmit && endpoint.connection.awaitsConfirmation()) {
        endpoint.emittedAt = ++emissions_;
    }
    return output;
}

CanSeiServer::Output CanSeiServer::onFrame(const can::CanFrame& frame, uint64_t nowNs)
{
    const can::LinkResult<MessageIdentifier> identifier = MessageIdentifier::fromFrame(frame);
    if (!identifier.ok() || identifier.value().type() != can::MessageType::Configuration) {
        ++ignored_;
        return {};
    }
    followSelection();
    Output output;
    if (!identifier.value().isBroadcast()) {
        output = track(own_, own_.connection.onFrame(frame, nowNs));
    } else if (singleFrameLength(frame) != 0 && isScanCommand(frame.data()[1])) {
        output = scan(frame, identifier.value().source(), identifier.value().priority(), nowNs);
    } else if (broadcast_.connection.isOpen()) {
        output = track(broadcast_, broadcast_.connection.onFrame(frame, nowNs));
    } else {
        ++ignored_;
    }
    // A Select or Deselect, to whichever address, opens or closes the
    // connection on the broadcast address.
    followSelection();
    return output;
}

CanSeiServer::Output CanSeiServer::scan(const can::CanFrame& frame, uint8_t host, uint8_t priority, uint64_t nowNs)
{
    ++scans_;
    uint8_t bytes[can::CanFrame::kMaxDataLength] = {};
    const uint8_t length = singleFrameLength(frame);
    const size_t replyLength =
        server_.handle(frame.data() + 1, length, bytes + 1, can::IsoTpPci::kMaxSingleFrameData, nowNs);
    if (replyLength == 0) {
        return {};
    }
    ++scanAnswers_;
    // A single frame, outside any connection: nothing waits for its
    // confirmation, and the host's time-out is its own.
    bytes[0] = can::IsoTpPci::pciByte(can::PciType::SingleFrame, static_cast<uint8_t>(replyLength));
    const can::IsoTpConfig answer = canSeiConnection(MessageIdentifier::kBroadcast, host, priority, false);
    Output output;
    output.transmit = true;
    output.frame = can::IsoTpPci::makeFrame(answer.txId, can::IdFormat::Extended, bytes,
                                            static_cast<uint8_t>(replyLength + 1), answer.padding);
    return output;
}

CanSeiServer::Output CanSeiServer::onTransmitConfirmed(uint64_t nowNs)
{
    followSelection();
    const bool own = own_.connection.awaitsConfirmation();
    const bool broadcast = broadcast_.connection.awaitsConfirmation();
    if (!own && !broadcast) {
        return {}; // A flow control or a scan's answer went: nothing waits for it.
    }
    // Frames go on the bus in the order they were handed over; the signed
    // distance keeps that order across the counter's wrap.
    const bool ownFirst = own && (!broadcast || static_cast<int32_t>(own_.emittedAt - broadcast_.emittedAt) < 0);
    Endpoint& endpoint = ownFirst ? own_ : broadcast_;
    return track(endpoint, endpoint.connection.onTransmitConfirmed(nowNs));
}

CanSeiServer::Output CanSeiServer::poll(uint64_t nowNs)
{
    followSelection();
    const Output own = track(own_, own_.connection.poll(nowNs));
    if (own.transmit) {
        return own;
    }
    return track(broadcast_, broadcast_.connection.poll(nowNs));
}

uint64_t CanSeiServer::nextDeadlineNs() const
{
    const uint64_t own = own_.connection.nextDeadlineNs();
    const uint64_t broadcast = broadcast_.connection.nextDeadlineNs();
    return own < broadcast ? own : broadcast;
}

CanSeiStatistics CanSeiServer::statistics() const
{
    CanSeiStatistics statistics;
    statistics.own = own_.connection.statistics();
    statistics.broadcast = broadcast_.connection.statistics();
    statistics.scans = scans_;
    statistics.scanAnswers = scanAnswers_;
    statistics.ignored = ignored_;
    return statistics;
}

} // namespace sei
