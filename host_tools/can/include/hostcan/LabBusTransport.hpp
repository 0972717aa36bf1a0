// A participant of the lab's CAN bus hub (docs/protocols/labbus.md,
// "Joining from a host tool"): the host tools reach the emulated
// controllers' buses as they reach a SocketCAN interface, and see the
// frames with their exact emulated completion times.
//
// The transport joins as a "host" participant without emulated time: its
// frames enter the bus at the next quantum boundary the boards reach, and it
// never holds the boards' clocks. It acknowledges frames like any node.
// send() returns once the hub says the frame is on the bus (TXOK), or why it
// is not (no acknowledge and given up, lost, aborted), within its time-out:
// a tool that leaves right after sending must not take its frame with it.
#pragma once

#include <hostcan/Transport.hpp>

#include <deque>

namespace hostcan {

class LabBusTransport final : public Transport {
public:
    /// How long the hub has to answer HELLO and ATTACH.
    static constexpr std::chrono::milliseconds kReplyTimeout{5000};

    /// Connects to the hub at @p socketPath and attaches to @p bus.
    static std::unique_ptr<LabBusTransport> open(const std::string& socketPath, const std::string& bus,
                                                 TransportError& error);
    ~LabBusTransport() override;

    std::string name() const override { return "lab:" + bus_; }
    TransportError send(const can::CanFrame& frame, std::chrono::milliseconds timeout) override;
    Received receive(std::chrono::milliseconds timeout, TransportError& error) override;
    std::optional<uint32_t> bitRate() const override;

    /// Parses one event line of the hub into what a transport reports;
    /// nothing for the events a transport does not report (SOF, IDLE, TXOK, ...).
    /// Exposed for the host tests.
    static std::optional<Received> parseEvent(const std::string& line, TransportError& error);

    /// The hub's text form of a frame: `<id hex> <SD|SR|XD|XR> <dlc> <data hex or ->`.
    static std::string frameWords(const can::CanFrame& frame);

private:
    LabBusTransport(int fd, std::string bus) : fd_(fd), bus_(std::move(bus)) {}

    TransportError writeLine(const std::string& line);
    std::optional<std::string> readLine(std::chrono::steady_clock::time_point deadline, TransportError& error);

    int fd_;
    std::string bus_;
    uint64_t bitNs_ = 0;
    std::string unread_;
    std::deque<Received> pending_; // Frames and events read while send() waited for its TXOK.
};

} // namespace hostcan
