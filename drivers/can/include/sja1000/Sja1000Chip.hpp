// The SJA1000 chip core: register access in PeliCAN mode, nothing else.
//
// Sja1000Chip knows the register map (sja1000/Sja1000Registers.hpp) and the
// layout of the frame buffer, and nothing of tasks, interrupts or the system
// agent; Sja1000Controller builds the DCOS device on top of it. A bus front
// end (the ISA card's ports, later a PCI card's BAR) hands it an
// arch_x86::IoWindow, so the host tests drive it through the recording port
// mock and check the exact register sequence of every operation, as Linux's
// and Zephyr's SJA1000 drivers split one chip core from thin bus glue.
#pragma once

#include <sja1000/BitTiming.hpp>
#include <sja1000/Sja1000Registers.hpp>

#include <arch_x86/IoWindow.hpp>
#include <can/CanFrame.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace sja1000 {

/// The identifier formats a channel takes, which the chip's filter alone
/// cannot choose (see AcceptanceFilter).
enum class FrameFormats : uint8_t {
    Both = 0,     ///< Standard and extended frames.
    Extended = 1, ///< Extended (29-bit) frames only, as DCOS sends them.
    Standard = 2, ///< Standard (11-bit) frames only.
};

/// The single 32-bit acceptance filter (MOD.AFM set, DS 6.4.15): a received
/// frame is taken when its bits equal `code` wherever `mask` has a 0. The
/// layout is the chip's, left-aligned: an extended identifier in bits 31:3
/// and the RTR bit in bit 2; a standard identifier in bits 31:21, RTR in
/// bit 20, then its first two data bytes.
///
/// The chip compares every frame in the layout of its own format, so a
/// filter written for extended identifiers also takes the standard frames
/// whose 11 bits, RTR and first data bytes fall on the same positions: the
/// chip has no format bit to compare. `formats` is that bit, checked by the
/// driver: a frame of another format is an identifier the channel did not
/// ask for, and is dropped and counted (ChannelStatistics::badIdentifiers).
struct AcceptanceFilter {
    uint32_t code = 0;
    uint32_t mask = 0xFFFFFFFF; ///< Every bit "don't care": the default takes every frame.
    FrameFormats formats = FrameFormats::Both;

    /// Takes every frame.
    static constexpr AcceptanceFilter all() { return {}; }
    /// Takes extended data and remote frames whose identifier matches
    /// @p id in the bits set in @p idMask, and no standard frame.
    static constexpr AcceptanceFilter extended(uint32_t id, uint32_t idMask)
    {
        return {(id & can::CanFrame::kMaxExtendedId) << 3, ~((idMask & can::CanFrame::kMaxExtendedId) << 3),
                FrameFormats::Extended};
    }
    /// Takes standard data and remote frames whose identifier matches @p id
    /// in the bits set in @p idMask, whatever their data, and no extended frame.
    static constexpr AcceptanceFilter standard(uint32_t id, uint32_t idMask)
    {
        return {(id & can::CanFrame::kMaxStandardId) << 21, ~((idMask & can::CanFrame::kMaxStandardId) << 21),
                FrameFormats::Standard};
    }
    /// Whether a frame's format is one the filter takes.
    constexpr bool takesFormat(bool extendedFrame) const
    {
        return formats == FrameFormats::Both || (formats == FrameFormats::Extended) == extendedFrame;
    }
};

/// How the chip takes part in the bus (MOD, DS 6.4.3).
enum class BusMode : uint8_t {
    Normal,     ///< Send and acknowledge.
    ListenOnly, ///< Receive only; no acknowledge, no error frames.
    SelfTest,   ///< Transmissions complete without an acknowledge (a lone node's test).
};

/// The fault-confinement state the error counters put the chip in (ISO 11898-1).
enum class ErrorState : uint8_t {
    Active,  ///< Both counters below the warning limit.
    Warning, ///< A counter at or above the warning limit (SR.ES), still error-active.
    Passive, ///< A counter at 128 or above.
    BusOff,  ///< The transmit counter passed 255; the chip has left the bus (SR.BS).
};

struct ErrorCounters {
    uint8_t receive = 0;  ///< RXERR.
    uint8_t transmit = 0; ///< TXERR.
};

/// Register-level access to one SJA1000. Every function is a fixed, short
/// sequence of register accesses, or a loop with a fixed bound; none waits
/// on anything but the chip.
class Sja1000Chip {
public:
    /// How often a mode change is read back before it counts as failed (the
    /// chip takes one internal clock; Linux's driver allows a hundred reads).
    static constexpr unsigned kModeChangeReads = 100;

    /// A chip behind @p window, which covers reg::kWindowSize bytes.
    explicit constexpr Sja1000Chip(arch_x86::IoWindow window) : window_(window) {}

    /// Whether an SJA1000 answers: it must take reset mode and PeliCAN
    /// mode and read them back. NotFound on an empty bus (reads of 0xFF)
    /// or a chip that does not follow; the chip is left in reset mode.
    dcos::Status probe() const;

    /// Requests reset mode and reads MOD back until the chip is in it.
    /// Busy when it does not follow within kModeChangeReads reads.
    dcos::Status enterReset() const;

    /// Sets up the chip in reset mode: PeliCAN, @p timing, @p filter,
    /// the output control of a standard transceiver, the warning limit,
    /// cleared error counters and @p interrupts enabled. The chip stays in
    /// reset mode until start().
    dcos::Status configure(const BitTiming& timing, const AcceptanceFilter& filter, uint8_t interrupts) const;

    /// Leaves reset mode into @p mode, with the single acceptance filter.
    /// Busy when the chip does not follow within kModeChangeReads reads.
    dcos::Status start(BusMode mode) const;

    /// Whether MOD.RM is set (after a bus-off the chip sets it by itself).
    bool inReset() const;

    /// Writes @p frame into the transmit buffer (DS 6.4.13). The caller
    /// checked SR.TBS; the transmission starts with transmit().
    void writeTransmitBuffer(const can::CanFrame& frame) const;

    /// Requests the transmission of the transmit buffer: @p selfReception
    /// also receives it here (SRR), @p singleShot never repeats it after an
    /// error or a lost arbitration (TR+AT, DS 6.4.4).
    void transmit(bool selfReception = false, bool singleShot = false) const;

    /// Cancels a requested transmission that is not yet on the bus (CMR.AT).
    void abortTransmission() const;

    /// Reads the first message of the receive FIFO (DS 6.4.14) and releases
    /// it (CMR.RRB). InvalidArgument, with the message released all the
    /// same, when its data length code is above 8: the frame is dropped
    /// rather than passed on with a length no layer above expects.
    can::LinkResult<can::CanFrame> readReceiveBuffer() const;

    /// Clears the data overrun status (CMR.CDO).
    void clearOverrun() const;

    /// Reads IR; reading clears every interrupt but RI (DS 6.4.6).
    uint8_t interrupts() const;
    /// Reads SR.
    uint8_t status() const;
    /// Reads RXERR and TXERR.
    ErrorCounters errorCounters() const;
    /// Reads ECC, which frees it for the next bus error (DS 6.4.9).
    uint8_t errorCode() const;
    /// Reads ALC, which frees it for the next lost arbitration (DS 6.4.8).
    uint8_t arbitrationLostBit() const;
    /// The number of messages in the receive FIFO (RMC).
    uint8_t receivedMessages() const;

    /// The fault-confinement state from SR and the counters.
    ErrorState errorState() const;

    /// The window the chip is reached through.
    constexpr const arch_x86::IoWindow& window() const { return window_; }

private:
    uint8_t read(uint8_t offset) const { return window_.read8(offset); }
    void write(uint8_t offset, uint8_t value) const { window_.write8(offset, value); }

    arch_x86::IoWindow window_;
};

} // namespace sja1000
