#include <flash/CanFlashServer.hpp>

#include <can/MessageIdentifier.hpp>

namespace flash {

can::IsoTpConfig canFlashConnection(uint8_t node, uint8_t host, uint8_t priority, bool hostSide)
{
    return can::isoTpRequestConnection(can::MessageType::Flashing, node, host, priority, hostSide, kCanNodeBlockSize);
}

CanFlashServer::CanFlashServer(FlashSession& session, uint8_t ownNode)
    : session_(session),
      server_(*this, can::MessageType::Flashing, kCanNodeBlockSize, request_, sizeof request_, reply_, sizeof reply_)
{
    setOwnNode(ownNode);
}

void CanFlashServer::setOwnNode(uint8_t ownNode)
{
    if (ownNode == can::MessageIdentifier::kBroadcast) {
        server_.close();
    } else {
        server_.open(ownNode);
    }
}

size_t CanFlashServer::handleRequest(const uint8_t* request, size_t length, uint8_t* reply, size_t capacity,
                                     uint64_t)
{
    const size_t replyLength = session_.handle(request, length, reply, capacity);
    RestartTarget target{};
    replyingToRestart_ = session_.restartRequested(target);
    return replyLength;
}

void CanFlashServer::replyEnded(bool)
{
    if (replyingToRestart_) {
        restartDue_ = true;
    }
}

bool CanFlashServer::restartDue(RestartTarget& target) const
{
    return restartDue_ && session_.restartRequested(target);
}

} // namespace flash
