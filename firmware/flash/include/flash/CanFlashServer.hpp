// The node's end of the flash protocol on CAN (docs/protocols/flash.md,
// "On CAN"): ISO 15765-2 transfers of the protocol's messages in frames of
// the DCOS message type Flashing, served by a FlashSession.
//
// A host tool (CAN node number h) asks node n with frames whose identifier
// is MessageIdentifier(p, Flashing, n, h); the node answers, and sends its
// flow control, on MessageIdentifier(p, Flashing, h, n): the same priority,
// the addresses swapped. That is one ISO-TP connection, which a Linux
// can-isotp socket opens with those two identifiers. p is the host's
// choice; dcos-flash uses 31, the least urgent, so an update never delays
// a control task's frame (seed 6.4: the task priority is the bus
// priority, and flashing is background work).
//
// The connection itself is the link layer's generic request server
// (can::IsoTpRequestServer), which the configuration protocol shares; this
// class gives it the flash protocol's message type and block size, and
// hands it the session. Pure code, with no controller and no clock of its
// own: the caller feeds it the frames received, the moment its last emitted
// frame was sent, and the time; it answers each input with at most one
// frame to transmit. The kernel's flash service (FlashService.cpp) and the
// stage loader's polled recovery both run it, and the host tests run it
// against the host's own ISO-TP.
//
// One connection at a time: a single or first frame from another host (or
// at another priority) ends the old connection and begins the new one, as
// a new Hello on the serial line does. A request that arrives while the
// reply to the last one is still being sent ends that reply: its host has
// stopped waiting for it. Flashing frames are never broadcast: a server
// whose own node is 255 (the kernel service's before it knows its
// interface) serves nothing.
#pragma once

#include <flash/FlashMessage.hpp>
#include <flash/FlashSession.hpp>

#include <can/CanFrame.hpp>
#include <can/IsoTpConfig.hpp>
#include <can/IsoTpRequestServer.hpp>
#include <can/IsoTpSender.hpp>

#include <stddef.h>
#include <stdint.h>

namespace flash {

/// The bus priority dcos-flash sends at unless told otherwise: the least urgent.
constexpr uint8_t kCanFlashPriority = 31;
/// The CAN node number dcos-flash takes on the bus unless told otherwise.
constexpr uint8_t kCanHostNode = 254;
/// Consecutive frames a node takes between its flow controls: small enough
/// that a node whose flash task is held up by control work loses no frame
/// of a block in its queue (FlashService.cpp holds 64).
constexpr uint8_t kCanNodeBlockSize = 16;

/// The ISO-TP connection between host @p host and node @p node at @p
/// priority, as the node sees it (it sends to the host), or as the host
/// sees it (@p hostSide: it sends to the node). Both ends time out after
/// ISO 15765-2's 1000 ms.
can::IsoTpConfig canFlashConnection(uint8_t node, uint8_t host, uint8_t priority, bool hostSide);

using CanFlashStatistics = can::IsoTpRequestStatistics;

class CanFlashServer : private can::IsoTpRequestHandler {
public:
    /// What one input asks of the caller.
    using Output = can::IsoTpRequestServer::Output;

    /// Serves @p session to hosts on the bus as CAN node @p ownNode.
    CanFlashServer(FlashSession& session, uint8_t ownNode);

    /// A frame from the bus, any frame: only the flash protocol's frames to
    /// this node are taken.
    Output onFrame(const can::CanFrame& frame, uint64_t nowNs) { return server_.onFrame(frame, nowNs); }
    /// The last frame this server asked to transmit is on the bus.
    Output onTransmitConfirmed(uint64_t nowNs) { return server_.onTransmitConfirmed(nowNs); }
    /// Lets time pass; call it at nextDeadlineNs() or later.
    Output poll(uint64_t nowNs) { return server_.poll(nowNs); }
    /// When poll() has something to do, or can::IsoTpSender::kNoDeadline.
    uint64_t nextDeadlineNs() const { return server_.nextDeadlineNs(); }

    /// True, with the target, once the reply to a Restart has been sent (or
    /// its sending given up): the caller restarts the node now.
    bool restartDue(RestartTarget& target) const;

    /// Answers as CAN node @p ownNode from now on; a connection under the
    /// old number ends.
    void setOwnNode(uint8_t ownNode);

    /// The host of the current connection (valid after the first request).
    uint8_t peer() const { return server_.peer(); }
    /// Whether a request or reply is on its way.
    bool busy() const { return server_.busy(); }
    const CanFlashStatistics& statistics() const { return server_.statistics(); }

private:
    size_t handleRequest(const uint8_t* request, size_t length, uint8_t* reply, size_t capacity,
                         uint64_t nowNs) override;
    void replyEnded(bool sent) override;

    FlashSession& session_;
    bool replyingToRestart_ = false;
    bool restartDue_ = false;
    uint8_t request_[kMaxMessage] = {};
    uint8_t reply_[kMaxMessage] = {};
    can::IsoTpRequestServer server_;
};

} // namespace flash
