// A Modbus serial-line slave ([SL] 2.4.2): frames from the transport in,
// responses from the server out, addressed as [SL] 2.2 says.
//
//   - a frame to this slave's address (1..247) is served and answered;
//   - a broadcast (address 0) of a write function (05, 06, 0F, 10) is
//     executed without a response; any other broadcast is ignored, since no
//     slave may answer one and a read that cannot be answered does nothing;
//   - a frame to another address is ignored.
// While its response is on the line (until onTransmitDone()) the slave is
// half duplex and drops what it receives: on RS-485 that can only be its own
// echo or a master that broke the protocol.
//
// Counters follow function 08's sub-functions ([AP] 6.8): 0x0E (messages
// processed), 0x0D (exceptions answered), 0x0F (messages without response);
// the line's counters are the transport's.
#pragma once

#include <modbus/ModbusResult.hpp>
#include <modbus/Server.hpp>
#include <modbus/StationStep.hpp>
#include <modbus/Transport.hpp>

namespace modbus {

class Slave {
public:
    struct Counters {
        uint32_t messages = 0;          ///< Frames to this slave or broadcast, processed (0x0E).
        uint32_t exceptions = 0;        ///< Exception responses sent (0x0D).
        uint32_t noResponses = 0;       ///< Processed frames that got no response: broadcasts (0x0F).
        uint32_t otherAddresses = 0;    ///< Frames to other slaves, ignored.
        uint32_t droppedWhileSending = 0;  ///< Frames received while a response was on the line.
    };

    /// A placeholder; only a target for assignment.
    Slave() = default;

    /// A slave at @p address (1..247, else InvalidSlaveAddress) serving
    /// @p server over @p transport; both outlive the slave.
    static ModbusResult<Slave> create(Transport& transport, Server& server, uint8_t address);

    /// Bytes received from the line at @p nowNs.
    StationStep onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs);

    /// Lets time pass: a request completes t3.5 after its last byte.
    StationStep poll(uint64_t nowNs);

    /// The response handed over by the last step has left the line at
    /// @p nowNs; NotExpected when none was being sent.
    ModbusError onTransmitDone(uint64_t nowNs);

    /// When poll() has something to do, or ~0.
    uint64_t nextDeadlineNs() const { return transport_ != nullptr ? transport_->nextDeadlineNs() : ~0ull; }
    /// Whether a response is on the line.
    bool transmitting() const { return transmitting_; }
    uint8_t address() const { return address_; }
    const Counters& counters() const { return counters_; }

private:
    StationStep serve();

    Transport* transport_ = nullptr;
    Server* server_ = nullptr;
    uint8_t address_ = 0;
    bool transmitting_ = false;
    Counters counters_;
    uint8_t response_[kMaxPduLength] = {};
    uint8_t adu_[kMaxAduLength] = {};
};

} // namespace modbus
