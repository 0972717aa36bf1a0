// Reservation of ISA I/O port ranges and interrupt lines.
//
// ISA boards are configured by switches and jumpers, so nothing on the bus
// stops two drivers from being set up on the same ports or line. Every ISA
// driver reserves its resources here before touching the hardware; a
// request that overlaps a reservation is refused with AlreadyExists and an
// IsaConflict naming both claimants, which the caller prints, e.g.
//
//     ports 0x300-0x33f wanted by mfio0 are held by ne2000 (0x300-0x31f)
//
// isaResources() is the board's own manager. On first use it registers the
// devices fixed on the 486 board: the interrupt controllers, the interval
// timer, COM1, the CMOS real-time clock and the emulator's isa-debug-exit.
// The table is fixed in size, every function runs in bounded time with
// interrupts briefly disabled, and nothing is allocated.
#pragma once

#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace iobus {

/// An inclusive range of I/O ports.
struct PortRange {
    uint16_t first; ///< The lowest port.
    uint16_t last;  ///< The highest port (inclusive).

    /// True when the two ranges share a port.
    constexpr bool overlaps(const PortRange& other) const { return first <= other.last && other.first <= last; }
};

/// No interrupt line.
constexpr uint8_t kNoIrq = 0xFF;

/// Why a reservation was refused: who asked for what, and who holds it.
struct IsaConflict {
    /// True when the conflict is over an interrupt line, false for ports.
    bool irq = false;
    /// The claimant that asked.
    char wantedBy[16] = {};
    /// What it asked for (ports, or the line in .line).
    PortRange wanted{0, 0};
    uint8_t wantedLine = kNoIrq;
    /// The claimant holding the resource.
    char heldBy[16] = {};
    /// What the holder has reserved (the holder's whole range, or its line).
    PortRange held{0, 0};
    uint8_t heldLine = kNoIrq;
};

/// One reservation: a port range, a line, or both, for one claimant.
struct IsaReservation {
    char claimant[16];  ///< The claimant's name, at most 15 characters.
    bool hasPorts;      ///< ports is valid.
    PortRange ports;    ///< The reserved ports.
    uint8_t line;       ///< The reserved interrupt line, or kNoIrq.
};

/// A table of ISA reservations.
class IsaResourceManager {
public:
    /// The most reservations the table holds.
    static constexpr size_t kCapacity = 24;
    /// The number of ISA interrupt lines (0-15).
    static constexpr uint8_t kLineCount = 16;

    /// An empty table.
    constexpr IsaResourceManager() = default;

    /// Reserves @p size ports from @p first and, unless @p line is kNoIrq,
    /// the interrupt line @p line, for @p claimant, all or nothing.
    ///
    /// Fails with InvalidArgument for a null or empty claimant or one longer
    /// than 15 characters, a zero size, a range past port 0xFFFF or a line
    /// above 15; AlreadyExists when the ports or the line overlap another
    /// claimant's reservation, filling @p conflict (when not null) with both
    /// sides; TableFull when every entry is used. A claimant may hold
    /// several reservations, but its own overlapping requests also conflict.
    dcos::Status reserve(const char* claimant, uint16_t first, uint16_t size, uint8_t line, IsaConflict* conflict);

    /// Reserves only the interrupt line @p line for @p claimant.
    dcos::Status reserveLine(const char* claimant, uint8_t line, IsaConflict* conflict);

    /// Gives back every reservation of @p claimant; returns how many were released.
    size_t release(const char* claimant);

    /// The number of reservations.
    size_t count() const { return count_; }

    /// Copies reservation @p index (0 to count() - 1) into @p out; false past the end.
    bool entry(size_t index, IsaReservation& out) const;

    /// Formats @p conflict as one line without a line ending, for example
    /// "ports 0x300-0x33f wanted by mfio0 are held by com1 (0x3f8-0x3ff)" or
    /// "IRQ 4 wanted by mfio0 is held by com1". Returns the full length, like snprintf.
    static size_t describe(const IsaConflict& conflict, char* buffer, size_t capacity);

    /// Registers the fixed devices of the 486 board unless already done.
    void registerBoardDevices();

private:
    dcos::Status add(const char* claimant, bool hasPorts, PortRange ports, uint8_t line, IsaConflict* conflict);

    IsaReservation entries_[kCapacity] = {};
    size_t count_ = 0;
    bool boardDevicesRegistered_ = false;
};

/// The board's resource manager, with its fixed devices registered.
IsaResourceManager& isaResources();

} // namespace iobus
