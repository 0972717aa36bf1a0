// A register-level stand-in for one SJA1000 in PeliCAN mode, answering the
// recording port mock, for the host tests of the chip core and controller.
//
// It keeps the registers a driver sees and follows the data sheet where the
// driver depends on it: reset mode gates the configuration registers, IR
// clears on read except RI, RI follows the receive FIFO, a transmission
// request clears TBS until the test says how the frame fared, an abort
// frees the buffer with TCS clear, and bus-off sets BS and reset mode. The
// bus itself is the test: it completes, aborts or fails transmissions and
// delivers frames with the functions below.
#pragma once

#include <sja1000/Sja1000Registers.hpp>

#include "../../../firmware/arch_x86/unit_tests/PortIoMock.hpp"

#include <can/CanFrame.hpp>

#include <cstdint>
#include <deque>
#include <vector>

namespace sja1000_test {

constexpr uint16_t kBase = 0x280;
constexpr uint8_t kIrq = 10;

class FakeSja1000 final : public port_io_mock::Responder {
public:
    FakeSja1000() { port_io_mock::attach(kBase, sja1000::reg::kWindowSize, this); }

    uint32_t read(uint16_t offset, int width) override;
    void write(uint16_t offset, uint32_t value, int width) override;

    // -- the bus, as the test plays it --------------------------------------

    /// The frame the last transmission request put on the bus.
    can::CanFrame transmitted() const;
    /// Whether a transmission request is pending (TR written, not yet finished).
    bool transmitting() const { return transmitPending; }
    /// The pending transmission succeeded: TCS, TBS and TI.
    void completeTransmission();
    /// A frame arrives and passes the acceptance filter: into the FIFO, RI.
    void receive(const can::CanFrame& frame);
    /// A frame arrives with a raw frame information byte (e.g. a DLC above 8).
    void receiveRaw(uint8_t information, const std::vector<uint8_t>& identifierAndData);
    /// The pending transmission found no acknowledge: TEC + 8, ECC, BEI.
    void acknowledgeError();
    /// The counters cross into error-passive (EPI) or back.
    void setCounters(uint8_t receive, uint8_t transmit);
    /// Bus-off: BS, reset mode, EI.
    void busOff();
    /// The chip overran its FIFO: DOS, DOI.
    void overrun();

    // -- what the driver wrote -------------------------------------------------
    uint8_t mode = sja1000::reg::kModeReset;
    uint8_t status = sja1000::reg::kStatusTransmitBuffer | sja1000::reg::kStatusTransmitComplete;
    uint8_t interrupt = 0;
    uint8_t interruptEnable = 0;
    uint8_t btr0 = 0;
    uint8_t btr1 = 0;
    uint8_t outputControl = 0;
    uint8_t clockDivider = 0;
    uint8_t errorWarningLimit = sja1000::reg::kDefaultErrorWarningLimit;
    uint8_t rxErrors = 0;
    uint8_t txErrors = 0;
    uint8_t errorCode = 0;
    uint8_t acceptance[8] = {};
    uint8_t transmitBuffer[13] = {};
    bool transmitPending = false;
    bool selfReception = false;
    bool singleShot = false;
    unsigned transmissionRequests = 0;
    unsigned aborts = 0;
    unsigned releases = 0;
    bool resetModeIgnored = false; ///< A chip that never leaves reset mode.

private:
    void raise(uint8_t bits);
    std::deque<std::vector<uint8_t>> fifo;
};

} // namespace sja1000_test
