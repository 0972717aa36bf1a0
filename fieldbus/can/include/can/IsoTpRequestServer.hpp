// A node's end of a request and reply protocol on ISO 15765-2: each request
// from a host is one ISO-TP transfer, answered by one transfer back. The
// flash protocol (docs/protocols/flash.md, "On CAN") and the configuration
// protocol (docs/protocols/config.md, "On CAN") both run on it; what a
// request means is the handler's (IsoTpRequestHandler).
//
// A host tool (CAN node number h) asks the node at address n with frames
// whose identifier is (p, type, n, h); the node answers, and sends its flow
// control, on (p, type, h, n): the same priority, the addresses swapped.
// That is one ISO-TP connection, which a Linux can-isotp socket opens with
// those two identifiers. p is the host's choice.
//
// Pure code, with no controller and no clock of its own, like the ISO-TP
// state machines it drives: the caller feeds it the frames received, the
// moment its last emitted frame was sent, and the time; it answers each
// input with at most one frame to transmit. The kernel's services, the
// stage loader's polled recovery and the host tests all run it the same way.
//
// One connection at a time: a single or first frame from another host (or
// at another priority) ends the old connection and begins the new one. A
// request that arrives while the reply to the last one is still being sent
// ends that reply: its host has stopped waiting for it.
//
// The address served is normally the node's own CAN node number. It may be
// the broadcast address 255, for the one protocol that answers there: the
// configuration protocol's selected node answers from source 255
// (docs/protocols/config.md, "Scanning"), an identifier that
// MessageIdentifier::make refuses and this class therefore builds itself.
#pragma once

#include <can/CanFrame.hpp>
#include <can/IsoTpConfig.hpp>
#include <can/IsoTpReceiver.hpp>
#include <can/IsoTpSender.hpp>
#include <can/MessageType.hpp>

#include <stddef.h>
#include <stdint.h>

namespace can {

/// The ISO-TP connection of a request and reply protocol of message type
/// @p type between host @p host and the node at address @p node (255 for a
/// node answering on the broadcast address) at @p priority, as the node sees
/// it (it sends to the host, and announces @p nodeBlockSize), or as the host
/// sees it (@p hostSide: it sends to the node, block size 0). Both ends time
/// out after ISO 15765-2's 1000 ms. A priority above 31 or a host of 255
/// leaves both identifiers 0, which no DCOS frame uses.
IsoTpConfig isoTpRequestConnection(MessageType type, uint8_t node, uint8_t host, uint8_t priority, bool hostSide,
                                   uint8_t nodeBlockSize);

/// What a request server asks of the protocol it carries.
class IsoTpRequestHandler {
public:
    /// Answers one whole request of @p length bytes with a reply written to
    /// @p reply; the reply's length, or 0 to answer nothing.
    virtual size_t handleRequest(const uint8_t* request, size_t length, uint8_t* reply, size_t capacity,
                                 uint64_t nowNs) = 0;
    /// The reply to the last request is over: sent whole (@p sent), or given
    /// up (a time-out, a new request, a new connection, the server closed).
    virtual void replyEnded(bool sent) = 0;

protected:
    ~IsoTpRequestHandler() = default;
};

struct IsoTpRequestStatistics {
    uint32_t requests = 0;    ///< Requests received whole and answered.
    uint32_t replies = 0;     ///< Replies sent whole.
    uint32_t aborted = 0;     ///< Transfers ended without their message (time-outs, sequence errors, a new request).
    uint32_t ignored = 0;     ///< Frames not for this server, or refused by ISO-TP.
    uint32_t connections = 0; ///< Connections begun with a new host or priority.
};

class IsoTpRequestServer {
public:
    /// What one input asks of the caller.
    struct Output {
        bool transmit = false; ///< Send `frame` now, and report with onTransmitConfirmed when it went.
        CanFrame frame;
    };

    /// A server of requests of message type @p type, answered by @p handler,
    /// announcing @p blockSize in its flow control. Requests are assembled in
    /// @p request and replies written to @p reply, both the caller's and kept
    /// for the server's life. It serves no address until open().
    IsoTpRequestServer(IsoTpRequestHandler& handler, MessageType type, uint8_t blockSize, uint8_t* request,
                       size_t requestCapacity, uint8_t* reply, size_t replyCapacity)
        : handler_(handler), type_(type), blockSize_(blockSize), request_(request),
          requestCapacity_(requestCapacity), reply_(reply), replyCapacity_(replyCapacity)
    {
    }

    /// Serves requests to @p address from now on; a connection under another
    /// address ends.
    void open(uint8_t address);
    /// Serves nothing any more; a connection ends.
    void close();
    bool isOpen() const { return open_; }
    /// The address served (meaningful while open).
    uint8_t address() const { return address_; }

    /// A frame from the bus, any frame: only frames of this server's message
    /// type to its address are taken.
    Output onFrame(const CanFrame& frame, uint64_t nowNs);
    /// The last frame this server asked to transmit is on the bus.
    Output onTransmitConfirmed(uint64_t nowNs);
    /// Lets time pass; call it at nextDeadlineNs() or later.
    Output poll(uint64_t nowNs);
    /// When poll() has something to do, or IsoTpSender::kNoDeadline.
    uint64_t nextDeadlineNs() const;

    /// The host of the current connection (valid after the first request).
    uint8_t peer() const { return peer_; }
    /// Whether a request or reply is on its way.
    bool busy() const { return !receiver_.idle() || !sender_.idle(); }
    /// Whether a frame of the reply was emitted and not confirmed yet: the
    /// next onTransmitConfirmed is for it. (A flow control of the receiver
    /// needs no confirmation.)
    bool awaitsConfirmation() const { return senderFrameOut_ && !sender_.idle(); }
    const IsoTpRequestStatistics& statistics() const { return statistics_; }

private:
    void connect(uint8_t host, uint8_t priority);
    void endConnection();
    void giveUpReply();
    Output afterReceive(const IsoTpStep& step, uint64_t nowNs);
    Output afterSend(const IsoTpStep& step);

    IsoTpRequestHandler& handler_;
    MessageType type_;
    uint8_t blockSize_;
    uint8_t* request_;
    size_t requestCapacity_;
    uint8_t* reply_;
    size_t replyCapacity_;
    bool open_ = false;
    uint8_t address_ = 0;
    bool connected_ = false;
    uint8_t peer_ = 0;
    uint8_t priority_ = 0;
    IsoTpReceiver receiver_;
    IsoTpSender sender_;
    bool senderFrameOut_ = false;
    IsoTpRequestStatistics statistics_;
};

} // namespace can
