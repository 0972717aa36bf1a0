// The chip core of the multi-function I/O board: register access only.
//
// MfioChip knows the register map (iobus/MfioRegisters.hpp) and nothing of
// tasks, interrupts or the system agent; MfioBoard builds the DCOS device on
// top of it. The bus front end hands it an arch_x86::IoWindow, so the host
// tests drive it through the recording port mock and check the exact
// register sequence of every operation.
#pragma once

#include <iobus/MfioRegisters.hpp>

#include <arch_x86/IoWindow.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace iobus {

/// What the identification registers report.
struct MfioIdentity {
    uint16_t id;       ///< `ID`, kBoardId on a present board.
    uint16_t revision; ///< `REVISION`: major in the high byte, minor in the low byte.
};

/// Register-level access to one board. Every function is a fixed, short
/// sequence of port accesses; none waits.
class MfioChip {
public:
    /// A chip behind @p window, which must cover mfio::kWindowSize bytes.
    explicit constexpr MfioChip(arch_x86::IoWindow window) : window_(window) {}

    /// Reads `ID` and `REVISION`. NotFound when `ID` is not the board's
    /// (an empty bus reads 0xFFFF); NotSupported for another major revision
    /// of the map. @p identity receives what was read in every case.
    dcos::Status probe(MfioIdentity& identity) const;

    /// Writes `CONTROL.RESET`: every register to its reset value.
    void reset() const;

    /// Writes `CONTROL`: @p interruptEnable sets `IRQ_ENABLE`.
    void setControl(bool interruptEnable) const;

    /// Reads `CONTROL`.
    uint16_t control() const;

    /// Reads `STATUS`.
    uint16_t status() const;

    /// Writes `ADC_START` with @p channel (0-7): starts a conversion at the
    /// channel's current gain. The board ignores it while `BUSY`.
    void startConversion(unsigned channel) const;

    /// Reads `ADC_DATA`: code, channel and overrange flag of the last result.
    uint16_t data() const;

    /// Writes `IRQ_ACK`: clears `DONE` and `IRQ_PENDING` and drops the request.
    void acknowledge() const;

    /// Writes the whole `GAIN` register (two bits per channel).
    void writeGains(uint16_t gains) const;

    /// Reads `GAIN`.
    uint16_t gains() const;

    /// Writes @p code (bits 11:0) to `DACn`, n = @p channel (0-7).
    void writeDac(unsigned channel, uint16_t code) const;

    /// Reads back `DACn`.
    uint16_t dac(unsigned channel) const;

    /// Reads `DI`.
    uint16_t digitalInputs() const;

    /// Writes `DO`.
    void writeDigitalOutputs(uint16_t bits) const;

    /// Reads back `DO`.
    uint16_t digitalOutputs() const;

    /// The window the chip is reached through.
    constexpr const arch_x86::IoWindow& window() const { return window_; }

private:
    arch_x86::IoWindow window_;
};

} // namespace iobus
