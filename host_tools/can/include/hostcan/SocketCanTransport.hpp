// A SocketCAN network interface through a raw CAN socket (Linux's can-raw),
// with every error class of the interface's error frames switched on, so
// that error-passive, bus-off and missing acknowledgements reach the tool
// as events, as candump -e shows them.
#pragma once

#include <hostcan/Transport.hpp>

#include <deque>
#include <vector>

namespace hostcan {

class SocketCanTransport final : public Transport {
public:
    /// Opens @p interface; NotAvailable when this kernel has no PF_CAN,
    /// Open when the interface does not exist or is down.
    static std::unique_ptr<SocketCanTransport> open(const std::string& interface, TransportError& error);
    ~SocketCanTransport() override;

    std::string name() const override { return interface_; }
    TransportError send(const can::CanFrame& frame, std::chrono::milliseconds timeout) override;
    Received receive(std::chrono::milliseconds timeout, TransportError& error) override;
    std::optional<uint32_t> bitRate() const override { return std::nullopt; }

private:
    SocketCanTransport(std::string interface, int fd) : interface_(std::move(interface)), fd_(fd) {}

    std::string interface_;
    int fd_;
    std::deque<Received> pending_; // Further events of an error frame that reported several.
};

/// Turns one Linux CAN error frame (linux/can/error.h) into the events it
/// reports; exposed for the host tests, which cannot make real ones here.
struct LinuxErrorFrame {
    uint32_t canId = 0;   ///< With CAN_ERR_FLAG and the CAN_ERR_* class bits.
    uint8_t data[8] = {};
};
std::vector<Received> decodeErrorFrame(const LinuxErrorFrame& frame);

} // namespace hostcan
