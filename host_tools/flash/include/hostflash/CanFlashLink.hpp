// The flash protocol on CAN (docs/protocols/flash.md, "On CAN"): each
// request and reply one ISO 15765-2 transfer on the connection between the
// tool's CAN node number and the node's, in frames of the DCOS message
// type Flashing. Through any hostcan transport (SocketCAN, slcan, the lab
// bus) with the link layer's own ISO-TP, or through the Linux kernel's
// can-isotp socket on a SocketCAN interface (--kernel-isotp).
#pragma once

#include <hostflash/FlashLink.hpp>

#include <hostcan/IsoTpRequester.hpp>

#include <flash/CanFlashServer.hpp>

#include <memory>
#include <string>

namespace hostflash {

struct CanFlashAddress {
    uint8_t node = 0;                              ///< The node's CAN node number.
    uint8_t host = flash::kCanHostNode;            ///< The tool's own.
    uint8_t priority = flash::kCanFlashPriority;   ///< The bus priority of both directions.
    bool kernelIsoTp = false;                      ///< Segment with the kernel's can-isotp socket.
};

class CanFlashLink final : public FlashLink {
public:
    /// Opens @p interface as `dcos-can -i` takes it (can0, slcan:/dev/ttyACM0,
    /// lab:/hub.sock:can0); null with @p error and @p why.
    static std::unique_ptr<CanFlashLink> open(const std::string& interface, const CanFlashAddress& address,
                                              LinkError& error, std::string& why);

    LinkError exchange(const flash::FlashMessage& request, flash::FlashMessage& reply,
                       std::chrono::milliseconds timeout, std::string& why) override;
    bool reachesRunningNode() const override { return true; }

private:
    explicit CanFlashLink(const CanFlashAddress& address) : address_(address) {}

    CanFlashAddress address_;
    std::unique_ptr<hostcan::IsoTpRequester> requester_;
};

} // namespace hostflash
