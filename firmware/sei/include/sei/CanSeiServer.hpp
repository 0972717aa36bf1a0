// The node's end of the configuration protocol on CAN
// (docs/protocols/config.md, "On CAN"): ISO 15765-2 transfers of the
// protocol's messages in frames of the DCOS message type Configuration,
// served by a SeiServer.
//
// A host tool (CAN node number h) asks node n on (p, Configuration, n, h)
// and the node answers, with its flow control, on (p, Configuration, h, n),
// exactly as the flash protocol's connection does (can::IsoTpRequestServer
// carries both). Besides that connection, the node takes part in scans on
// the broadcast address 255 ("Scanning"):
//
// - ProbeSerial, Select and Deselect sent to 255 as single frames are
//   answered outside any connection, with a single frame from source 255,
//   by every node the command matches (SeiServer decides): all of them
//   send the same identifier and the same bytes, so any number of them are
//   one frame on the bus.
// - While its SeiServer is the selected node, a second connection serves
//   every other request sent to 255 as if sent to the node, and answers
//   from source 255. A node not selected takes nothing else sent to 255.
//
// Same shape as flash::CanFlashServer, so the kernel's service drives it
// the same way: pure code, fed the frames received, the confirmations of
// the frames it asked to send, and the time; each input answers with at
// most one frame to transmit.
#pragma once

#include <sei/SeiMessage.hpp>
#include <sei/SeiServer.hpp>

#include <can/CanFrame.hpp>
#include <can/IsoTpConfig.hpp>
#include <can/IsoTpRequestServer.hpp>
#include <can/IsoTpSender.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

/// The bus priority dcos-config sends at unless told otherwise: the least urgent.
constexpr uint8_t kCanSeiPriority = 31;
/// The CAN node number dcos-config takes on the bus unless told otherwise.
constexpr uint8_t kCanSeiHostNode = 254;
/// Consecutive frames a node takes between its flow controls, as the flash
/// protocol's node (flash::kCanNodeBlockSize).
constexpr uint8_t kCanSeiNodeBlockSize = 16;
/// How long a host waits for the answers to a ProbeSerial.
constexpr uint64_t kCanSeiProbeWaitNs = 50ull * 1000000ull;

/// The ISO-TP connection between host @p host and node @p node at @p
/// priority, as the node sees it (it sends to the host), or as the host
/// sees it (@p hostSide: it sends to the node). @p node 255 is the
/// connection with the selected node on the broadcast address, which
/// answers from source 255. Both ends time out after ISO 15765-2's 1000 ms.
can::IsoTpConfig canSeiConnection(uint8_t node, uint8_t host, uint8_t priority, bool hostSide);

struct CanSeiStatistics {
    can::IsoTpRequestStatistics own;       ///< The connection on the node's own CAN node number.
    can::IsoTpRequestStatistics broadcast; ///< The selected node's connection on the broadcast address.
    uint32_t scans = 0;       ///< Scanning commands taken from the broadcast address.
    uint32_t scanAnswers = 0; ///< Of them, those this node answered.
    uint32_t ignored = 0;     ///< Frames neither connection nor a scan took (not Configuration, or to 255 unselected).
};

class CanSeiServer {
public:
    /// What one input asks of the caller.
    using Output = can::IsoTpRequestServer::Output;

    /// Serves @p server to hosts on the bus as CAN node @p ownNode (255:
    /// on no number of its own until setOwnNode).
    CanSeiServer(SeiServer& server, uint8_t ownNode);

    /// A frame from the bus, any frame: only the configuration protocol's
    /// frames to this node, and to the broadcast address, are taken.
    Output onFrame(const can::CanFrame& frame, uint64_t nowNs);
    /// The frame this server asked to transmit first, of those not
    /// confirmed yet, is on the bus.
    Output onTransmitConfirmed(uint64_t nowNs);
    /// Lets time pass; call it at nextDeadlineNs() or later (again at once
    /// while the deadline has passed: one frame per call).
    Output poll(uint64_t nowNs);
    /// When poll() has something to do, or can::IsoTpSender::kNoDeadline.
    uint64_t nextDeadlineNs() const;

    /// True once the reply to a Restart has been sent (or its sending given
    /// up): the caller restarts the node now.
    bool restartDue() const { return own_.restartDue || broadcast_.restartDue; }

    /// Answers as CAN node @p ownNode from now on; a connection under the
    /// old number ends.
    void setOwnNode(uint8_t ownNode);

    /// The host of the connection on the node's own number (valid after its first request).
    uint8_t peer() const { return own_.connection.peer(); }
    /// Whether a request or reply is on its way on either connection.
    bool busy() const { return own_.connection.busy() || broadcast_.connection.busy(); }
    CanSeiStatistics statistics() const;

private:
    // One connection of the protocol: its request server, the buffers it
    // assembles requests and writes replies in, and whether the reply on
    // its way answers a Restart.
    class Endpoint final : public can::IsoTpRequestHandler {
    public:
        explicit Endpoint(SeiServer& server);

        size_t handleRequest(const uint8_t* request, size_t length, uint8_t* reply, size_t capacity,
                             uint64_t nowNs) override;
        void replyEnded(bool sent) override;

        SeiServer& server;
        bool replyingToRestart = false;
        bool restartDue = false;
        /// When its reply's last frame was emitted, in emissions of this
        /// server: confirmations go to the connection that emitted first.
        uint32_t emittedAt = 0;
        uint8_t request[kSeiMaxMessage] = {};
        uint8_t reply[kSeiMaxMessage] = {};
        can::IsoTpRequestServer connection;
    };

    Output scan(const can::CanFrame& frame, uint8_t host, uint8_t priority, uint64_t nowNs);
    Output track(Endpoint& endpoint, const Output& output);
    void followSelection();

    SeiServer& server_;
    Endpoint own_;
    Endpoint broadcast_;
    uint32_t emissions_ = 0;
    uint32_t scans_ = 0;
    uint32_t scanAnswers_ = 0;
    uint32_t ignored_ = 0;
};

} // namespace sei
