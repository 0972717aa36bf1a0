// An slcan (Lawicel) adapter as a transport: CANable, USBtin and the like on
// a serial device, or the same protocol over a unix socket (an adapter that
// a lab program emulates, a serial server).
// The line protocol is the link layer's SlcanCodec (fieldbus/can), the same
// code the firmware would use as an adapter.
//
// Opening closes the channel (`C`), sets the bit rate (`Sn`) and opens it
// (`O`), and checks each reply: an adapter that answers BELL, or nothing
// within the time-out, is reported, not assumed to work.
#pragma once

#include <hostcan/Transport.hpp>

#include <can/SlcanCodec.hpp>

#include <deque>

namespace hostcan {

class SlcanTransport final : public Transport {
public:
    /// How long an adapter has to answer a command.
    static constexpr std::chrono::milliseconds kReplyTimeout{1000};

    /// Opens a serial device (@p isSocket false, 115200 baud 8N1 raw; USB
    /// adapters ignore the rate) or a unix stream socket, and brings the
    /// adapter onto the bus at @p bitRate (one of the `S0`-`S8` rates).
    static std::unique_ptr<SlcanTransport> open(const std::string& path, bool isSocket, uint32_t bitRate,
                                                TransportError& error);
    /// Takes an already open descriptor (a socketpair in the tests) and
    /// brings the adapter on it onto the bus.
    static std::unique_ptr<SlcanTransport> adopt(int fd, std::string name, uint32_t bitRate, TransportError& error);
    ~SlcanTransport() override;

    std::string name() const override { return name_; }
    TransportError send(const can::CanFrame& frame, std::chrono::milliseconds timeout) override;
    Received receive(std::chrono::milliseconds timeout, TransportError& error) override;
    std::optional<uint32_t> bitRate() const override { return bitRate_; }

    /// Lines the adapter sent that were refused, by reason.
    const can::SlcanCodec::Statistics& statistics() const { return codec_.statistics(); }

private:
    SlcanTransport(int fd, std::string name, uint32_t bitRate) : fd_(fd), name_(std::move(name)), bitRate_(bitRate) {}

    TransportError writeMessage(const can::SlcanMessage& message);
    TransportError command(const can::SlcanMessage& message, bool mustSucceed);
    // Reads bytes until a message is decoded or the deadline passes.
    std::optional<can::SlcanMessage> nextMessage(std::chrono::steady_clock::time_point deadline,
                                                 TransportError& error);

    int fd_;
    std::string name_;
    uint32_t bitRate_;
    can::SlcanCodec codec_;
    std::deque<uint8_t> unread_;
    std::deque<Received> pending_; // Frames that arrived while waiting for a command's reply.
};

} // namespace hostcan
