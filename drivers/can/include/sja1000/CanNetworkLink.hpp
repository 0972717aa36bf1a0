// A CAN channel as a link of the network interfaces manager (seed 7.13).
//
// It carries each system message in one extended data frame whose
// identifier is the message's priority, type, destination and source
// (can::MessageIdentifier, docs/protocols/can.md), and its bytes as the
// frame's data. It speaks to the channel's driver only through the system
// agent, by the device's id, so it works with any driver that moves
// can::CanFrame objects through Read and Write as Sja1000Controller does.
//
//     static sja1000::CanNetworkLink link0;
//     link0.bind(can0Device);                         // installed and open
//     NetworkInterfacesManager::AttachLink(0, link0);  // interface 0 is CAN
//
// From Start on, the channel's receive event goes to the remote agent's
// receiver task; frames that are not a system message for this node (other
// protocols on the bus, DCOS frames for other nodes, types that are not
// remote transactions) are dropped and counted.
#pragma once

#include <dcos/NetworkLink.hpp>
#include <dcos/ObjectId.hpp>

#include <stdint.h>

namespace sja1000 {

/// What a link dropped on reception, since it was bound.
struct CanLinkStatistics {
    uint32_t sent = 0;
    uint32_t received = 0;     ///< System messages handed to the remote agent.
    uint32_t foreign = 0;      ///< Frames that are no DCOS frame, or of another DCOS type.
    uint32_t otherNodes = 0;   ///< DCOS system messages for another node.
    uint32_t queueFull = 0;    ///< Sends the driver's transmit queue did not take.
    uint32_t stale = 0;        ///< Frames found waiting at Start, from before the link was attached, dropped.
    uint32_t echoes = 0;       ///< The node's own messages handed back with the moment they went.
};

class CanNetworkLink final : public dcos::NetworkLink {
public:
    constexpr CanNetworkLink() = default;

    /// Uses the CAN device @p device, which its owner has installed and
    /// opened. Only while no interface has the link.
    void bind(dcos::ObjectId device) { device_ = device; }
    dcos::ObjectId device() const { return device_; }
    /// True between Start and Stop.
    bool started() const { return started_; }
    CanLinkStatistics statistics() const { return statistics_; }

    dcos::Status Start(dcos::ObjectId receiver, uint32_t receiveEvent, uint32_t ownPhysical) override;
    void Stop() override;
    dcos::Status Send(const dcos::SystemMessage& message) override;
    dcos::Result<bool> Receive(dcos::SystemMessage& message) override;

private:
    dcos::ObjectId device_{};
    uint32_t ownPhysical_ = 0;
    bool started_ = false;
    CanLinkStatistics statistics_{};
};

} // namespace sja1000
