// A CAN channel as a network link (CanNetworkLink.hpp).
#include <sja1000/CanNetworkLink.hpp>
#include <sja1000/Sja1000Controller.hpp>

#include <can/CanFrame.hpp>
#include <can/MessageIdentifier.hpp>
#include <dcos/SystemAgent.hpp>

namespace sja1000 {

using dcos::Result;
using dcos::Status;

// The link passes the kernel's message types through as CAN message types.
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::TimeSync) ==
              static_cast<uint8_t>(can::MessageType::TimeSync));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::RemoteReply) ==
              static_cast<uint8_t>(can::MessageType::RemoteReply));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::RemoteRequest) ==
              static_cast<uint8_t>(can::MessageType::RemoteRequest));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::NameQuery) ==
              static_cast<uint8_t>(can::MessageType::NameQuery));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::RoutedRequest) ==
              static_cast<uint8_t>(can::MessageType::RoutedRequest));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::NodeStarted) ==
              static_cast<uint8_t>(can::MessageType::NodeStarted));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::DsmPublication) ==
              static_cast<uint8_t>(can::MessageType::DsmPublication));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::RelayedPublication) ==
              static_cast<uint8_t>(can::MessageType::RelayedPublication));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::Flashing) ==
              static_cast<uint8_t>(can::MessageType::Flashing));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::Configuration) ==
              static_cast<uint8_t>(can::MessageType::Configuration));
static_assert(static_cast<uint8_t>(dcos::SystemMessageType::Monitoring) ==
              static_cast<uint8_t>(can::MessageType::Monitoring));

namespace {

// The message types the kernel takes from a link.
bool isSystemMessage(can::MessageType type)
{
    return type == can::MessageType::RemoteRequest || type == can::MessageType::RemoteReply ||
           type == can::MessageType::NameQuery || type == can::MessageType::RoutedRequest ||
           type == can::MessageType::NodeStarted ||
           type == can::MessageType::DsmPublication || type == can::MessageType::RelayedPublication ||
           type == can::MessageType::TimeSync || type == can::MessageType::Flashing ||
           type == can::MessageType::Configuration;
}

} // namespace

Status CanNetworkLink::Start(dcos::ObjectId receiver, uint32_t receiveEvent, uint32_t ownPhysical)
{
    if (device_.isNull()) {
        return Status::InvalidId;
    }
    if (ownPhysical > can::MessageIdentifier::kMaxNodeNumber) {
        return Status::InvalidArgument; // Not a CAN node number.
    }
    Notification notification;
    notification.task = receiver;
    notification.receiveEvent = receiveEvent;
    const Status status =
        dcos::systemAgent.Control(device_, Sja1000Controller::kSetNotification, &notification, sizeof notification);
    if (status != Status::Ok) {
        return status;
    }
    // Frames that waited in the driver while no link was attached are old:
    // a request among them may have been given up by its sender long ago,
    // and must not be served now.
    TimedFrame stale;
    while (true) {
        const Result<size_t> read = dcos::systemAgent.Read(device_, Sja1000Controller::kTimedChannel, &stale,
                                                           sizeof stale);
        if (!read.ok() || read.value() == 0) {
            break;
        }
        ++statistics_.stale;
    }
    ownPhysical_ = ownPhysical;
    started_ = true;
    return Status::Ok;
}

void CanNetworkLink::Stop()
{
    if (!started_) {
        return;
    }
    Notification nobody;
    (void)dcos::systemAgent.Control(device_, Sja1000Controller::kSetNotification, &nobody, sizeof nobody);
    started_ = false;
}

Status CanNetworkLink::Send(const dcos::SystemMessage& message)
{
    if (!started_) {
        // Attached but not started yet (or stopped): its own node number is
        // not known, and a frame sent now would carry a wrong source.
        return Status::Busy;
    }
    const uint32_t destination =
        message.destination == dcos::NetworkLink::kBroadcast ? can::MessageIdentifier::kBroadcast : message.destination;
    if (destination > can::MessageIdentifier::kBroadcast || message.length > can::CanFrame::kMaxDataLength) {
        return Status::InvalidArgument;
    }
    const uint8_t source = message.source == dcos::NetworkLink::kBroadcast ? can::MessageIdentifier::kBroadcast
                                                                           : static_cast<uint8_t>(ownPhysical_);
    const can::LinkResult<can::MessageIdentifier> identifier = can::MessageIdentifier::make(
        message.priority, static_cast<can::MessageType>(message.type), static_cast<uint8_t>(destination), source);
    if (!identifier.ok()) {
        return Status::InvalidArgument;
    }
    const can::LinkResult<can::CanFrame> frame = can::CanFrame::makeData(
        identifier.value().encode(), can::IdFormat::Extended, message.data, message.length);
    if (!frame.ok()) {
        return Status::InvalidArgument;
    }
    // Frames written on the timed channel come back as echoes with the
    // moment they went (Sja1000Controller.hpp).
    const uint32_t channel = message.echo ? Sja1000Controller::kTimedChannel : Sja1000Controller::kFrameChannel;
    const Result<size_t> written = dcos::systemAgent.Write(device_, channel, &frame.value(), sizeof(can::CanFrame));
    if (!written.ok()) {
        return written.status();
    }
    if (written.value() != sizeof(can::CanFrame)) {
        ++statistics_.queueFull;
        return Status::Busy;
    }
    ++statistics_.sent;
    return Status::Ok;
}

Result<bool> CanNetworkLink::Receive(dcos::SystemMessage& message)
{
    for (;;) {
        TimedFrame timed;
        const Result<size_t> read =
            dcos::systemAgent.Read(device_, Sja1000Controller::kTimedChannel, &timed, sizeof timed);
        if (!read.ok()) {
            return read.status();
        }
        if (read.value() == 0) {
            return false;
        }
        const can::CanFrame& frame = timed.frame;
        const bool echo = (timed.flags & TimedFrame::kEcho) != 0;
        const can::LinkResult<can::MessageIdentifier> identifier = can::MessageIdentifier::fromFrame(frame);
        if (!identifier.ok() || !isSystemMessage(identifier.value().type())) {
            ++statistics_.foreign;
            continue;
        }
        const uint8_t destination = identifier.value().destination();
        if (!echo && destination != ownPhysical_ && destination != can::MessageIdentifier::kBroadcast) {
            ++statistics_.otherNodes;
            continue;
        }
        message.priority = identifier.value().priority();
        message.type = static_cast<dcos::SystemMessageType>(identifier.value().type());
        message.destination = destination == can::MessageIdentifier::kBroadcast ? dcos::NetworkLink::kBroadcast
                                                                                : destination;
        message.source = identifier.value().source();
        message.length = frame.length();
        __builtin_memcpy(message.data, frame.data(), frame.length());
        message.echo = echo;
        message.timeNs = timed.timeNs;
        message.instructionStamp = timed.instructionStamp;
        if (echo) {
            ++statistics_.echoes;
            return true;
        }
        ++statistics_.received;
        return true;
    }
}

} // namespace sja1000
