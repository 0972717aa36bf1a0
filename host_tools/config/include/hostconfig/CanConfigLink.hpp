// The configuration protocol on CAN (docs/protocols/config.md, "On CAN"):
// each request and reply one ISO 15765-2 transfer on the connection
// between the tool's CAN node number and the node's (or the broadcast
// address, where the selected node answers from 255), in frames of the
// DCOS message type Configuration, through hostcan::IsoTpRequester as
// dcos-flash's link does. The scan's ProbeSerial and the Deselect go to
// the broadcast address as single frames outside the connection, and the
// probes' answers are read as frames: through the requester's transport,
// or, when the kernel's can-isotp socket carries the connection
// (--kernel-isotp), through a raw socket of their own.
#pragma once

#include <hostconfig/ConfigLink.hpp>

#include <hostcan/IsoTpRequester.hpp>
#include <hostcan/Transport.hpp>

#include <can/IsoTpConfig.hpp>
#include <can/MessageIdentifier.hpp>
#include <sei/CanSeiServer.hpp>

#include <chrono>
#include <memory>
#include <string>

namespace hostconfig {

struct CanConfigAddress {
    /// The node's CAN node number, or the broadcast address 255: the
    /// selected node (and the scan).
    uint8_t node = can::MessageIdentifier::kBroadcast;
    uint8_t host = sei::kCanSeiHostNode;         ///< The tool's own.
    uint8_t priority = sei::kCanSeiPriority;     ///< The bus priority of both directions.
    bool kernelIsoTp = false;                    ///< Segment with the kernel's can-isotp socket.
    /// How long a probe waits for answers.
    std::chrono::milliseconds probeWait{sei::kCanSeiProbeWaitNs / 1000000};
};

/// The single frame that carries the @p length bytes at @p message (1 to
/// 7) to the broadcast address on @p broadcast, the broadcast address's
/// connection as the host sees it (sei::canSeiConnection(255, host,
/// priority, true)): a probe, a Deselect.
can::CanFrame broadcastFrame(const can::IsoTpConfig& broadcast, const uint8_t* message, uint8_t length);

/// Whether @p frame is a node's answer to a ProbeSerial of the host whose
/// broadcast connection is @p broadcast: the single frame [0xA0][Ok] from
/// source 255 (CanSeiServer sends it outside any connection).
bool isProbeAnswer(const can::CanFrame& frame, const can::IsoTpConfig& broadcast);

class CanConfigLink final : public ConfigLink {
public:
    /// Opens @p interface as `dcos-can -i` takes it (can0,
    /// slcan:/dev/ttyACM0, lab:/hub.sock:can0); null with @p error and @p why.
    static std::unique_ptr<CanConfigLink> open(const std::string& interface, const CanConfigAddress& address,
                                               LinkError& error, std::string& why);
    /// Over a transport already open (address.kernelIsoTp is not taken
    /// then); null with BadArgument for addresses no node could answer.
    static std::unique_ptr<CanConfigLink> over(std::unique_ptr<hostcan::Transport> transport,
                                               const CanConfigAddress& address, LinkError& error, std::string& why);

    /// The frame transport under the connection; null on the kernel's
    /// can-isotp socket.
    hostcan::Transport* transport() { return requester_->transport(); }

    LinkError exchange(const Bytes& request, sei::SeiCommand command, Bytes& reply, std::chrono::milliseconds timeout,
                       std::string& why) override;
    LinkError probe(uint8_t bits, uint32_t value, bool& answered, std::string& why) override;
    LinkError announce(const Bytes& request, std::string& why) override;

private:
    CanConfigLink(const std::string& interface, const CanConfigAddress& address);

    /// The transport for frames outside the connection; null with @p error
    /// and @p why when a raw socket beside the kernel's cannot be opened.
    hostcan::Transport* frames(LinkError& error, std::string& why);
    /// Sends the @p length bytes at @p message as one single frame to the
    /// broadcast address.
    LinkError sendBroadcast(const uint8_t* message, uint8_t length, std::string& why);

    std::string interface_;
    CanConfigAddress address_;
    /// The broadcast address's connection as the host sees it: the probes
    /// go on its txId, their answers come on its rxId.
    can::IsoTpConfig broadcast_;
    std::unique_ptr<hostcan::IsoTpRequester> requester_;
    std::unique_ptr<hostcan::Transport> raw_;
};

} // namespace hostconfig
