// The search for every serial number on a CAN bus (docs/protocols/config.md,
// "Scanning"): a binary search with ProbeSerial, as CANopen's LSS Fastscan
// makes one. A probe asks "does any node's serial number begin with these
// top bits?" and learns only yes or no, because every matching node sends
// the same answer frame and any number of them are one frame on the bus.
//
// The search walks the 32 bits from the top, depth first and the 0 branch
// first, so it finds the serial numbers in ascending order. It probes the 0
// branch of every prefix it knows to hold a node; when that branch is
// silent, the 1 branch must hold the node the prefix answered for, so it
// is taken without a probe of its own: one probe per bit, 33 or 34 for a
// bus with one node. A serial number reached by that inference alone is
// probed in full before it counts, so a node that leaves the bus during
// the search never leaves a serial number behind that no node has. When
// the 0 branch answers, the 1 branch is unknown and is probed.
//
// Pure code: the caller's probe function puts the question on the bus (or
// on a simulation) and says what came back.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace hostconfig {

class SerialSearch {
public:
    /// What one probe learned.
    enum class Answer {
        Match,  ///< At least one node answered.
        Silent, ///< No node answered in time.
        Failed, ///< The probe could not be sent; the search ends.
    };
    /// How a search ended.
    enum class Outcome {
        Done,    ///< Every serial number is in serials().
        Failed,  ///< A probe failed; serials() holds those found before.
        TooMany, ///< More serial numbers than the limit: something answers every probe.
    };

    /// Asks whether any node's serial number s (not 0) has
    /// (s & sei::seiProbeMask(bits)) == value.
    using Probe = std::function<Answer(uint8_t bits, uint32_t value)>;

    /// Far more nodes than a CAN bus carries: a search that finds more has
    /// met a device that answers whatever it is asked, and stops before it
    /// would probe for ever.
    static constexpr size_t kDefaultMaxSerials = 1024;

    explicit SerialSearch(Probe probe, size_t maxSerials = kDefaultMaxSerials);

    /// Runs the whole search from the top; may be run again.
    Outcome run();

    /// The serial numbers found, in ascending order.
    const std::vector<uint32_t>& serials() const { return serials_; }
    /// The probes the last run sent.
    unsigned probes() const { return probes_; }

private:
    Probe probe_;
    size_t maxSerials_;
    std::vector<uint32_t> serials_;
    unsigned probes_ = 0;
};

} // namespace hostconfig
