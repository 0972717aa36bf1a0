// The seed's Test Case 2 (9.4.2, Fig. 9.6) with plain tasks: a regulatory
// control loop of three components, each a task, joined by distributed
// shared memory publishers, so that one copy of the application runs with
// all three components on one node or split over nodes unchanged.
//
//     sampler --"pv"--> controller --"mv"--> actuator
//     AI0 every period    set point, P + feed-forward    AO0
//
// A component is given the ids of the publishers it reads; whether such an
// id names a local publisher or another node's is the DSM agent's business
// (docs/protocols/publications.md), not the component's.
#pragma once

#include <dcos/DsmAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace plant {

/// The sampler's period: one conversion and one publication.
constexpr uint64_t kPeriodNs = 10'000'000;
/// A reader that waits this long for a page counts a time-out and waits again.
constexpr uint64_t kReadTimeoutNs = 100'000'000;

/// A value on its way from the plant to the actuator: microvolts, and the
/// uptime of the sample it derives from, so the actuator, on the sampler's
/// node, sees the loop's delay through every component.
struct Signal {
    int32_t microvolts = 0;
    uint64_t sampledNs = 0;
};

/// The page layout, byte by byte so that any node reads it alike: bytes
/// 0-3 the microvolts, 4-11 the sample's uptime, both little-endian.
dcos::DsmPage encode(const Signal& signal);
Signal decode(const dcos::DsmPage& page);

/// What each component has done.
struct SamplerStatistics {
    uint32_t samples = 0;
    int32_t lastMicrovolts = 0;
    uint32_t errors = 0; ///< Conversions or Writes that failed.
};

struct ControllerStatistics {
    uint32_t cycles = 0;
    int32_t lastPv = 0;
    int32_t lastMv = 0;
    uint32_t timeouts = 0;
    uint32_t errors = 0;
};

struct ActuatorStatistics {
    uint32_t writes = 0;
    int32_t lastMv = 0;
    uint64_t lastDelayNs = 0; ///< From the sample to the DAC write (sampler on the same node).
    uint64_t maxDelayNs = 0;
    uint32_t timeouts = 0;
    uint32_t errors = 0;
    uint32_t failovers = 0; ///< Times the input it followed fell silent and the other took over.
};

/// Installs the I/O board (0x300, interrupt line 5) for the sampler and
/// the actuator; Ok when it is installed already.
dcos::Status installBoard();

/// Starts component 1: creates the global publisher "pv" and the sampler
/// task, which writes AI0 to it every kPeriodNs. Returns the publisher.
dcos::Result<dcos::ObjectId> startSampler();
/// Starts component 2: creates the global publisher "mv" and the controller
/// task, which reads @p pv and writes the controller output. Returns "mv".
dcos::Result<dcos::ObjectId> startController(dcos::ObjectId pv);
/// Starts component 3: the actuator task, which reads @p mv and writes AO0.
///
/// With a @p backup, a second controller's "mv" (active backup redundancy,
/// seed 9.4.3), the actuator follows one of the two and keeps the other's
/// pages read: when the one it follows is silent for kFailoverNs (its node
/// or its bus died), it follows the other from then on.
dcos::Status startActuator(dcos::ObjectId mv, dcos::ObjectId backup = dcos::ObjectId::null());

/// How long the followed controller may be silent before its twin takes over: three periods.
constexpr uint64_t kFailoverNs = 3 * kPeriodNs;

/// The seed's Test Case 3 (9.4.3): a voting subscriber. It reads two
/// samplers' "pv" publishers (two copies of component 1 on two nodes), votes
/// on the process value, computes the controller's output and writes it to
/// kVoterOutput, then reads that output back on kVoterReadBack. Two voters on
/// two nodes drive the plant together: the plant takes the higher of their
/// outputs (the lab wires them through diodes, host_tools/plant_simulator,
/// "Several boards"), so either carries the loop alone when the other dies.
///
/// The vote, each time the followed sampler's page arrives: when the other
/// sampler's page is fresh (it came within kFreshCycles cycles) and the two
/// agree within kAgreeMicrovolts, their mean; when they disagree, the one
/// nearer the value used last (a sensor that jumps away is the suspect);
/// when only the followed one is fresh, that one. When the followed sampler
/// is silent for kFailoverNs, the voter follows the other.
dcos::Status startVoter(dcos::ObjectId pv, dcos::ObjectId otherPv);

/// The voter's output channel (AO1) and the input that reads it back (AI1).
constexpr unsigned kVoterOutput = 1;
constexpr unsigned kVoterReadBack = 1;
/// Two samples of one process taken within a period agree within this.
constexpr int32_t kAgreeMicrovolts = 50'000;
/// The other sampler's page counts as fresh this many cycles after it came.
constexpr uint32_t kFreshCycles = 2;
/// A read-back further than this from the output written counts as an error:
/// two LSBs of the 12-bit DAC and ADC over 20 V, about 10 mV.
constexpr int32_t kReadBackToleranceMicrovolts = 10'000;

/// The voter's vote on one cycle: pure, so that the host can test it.
enum class VoteKind : uint8_t { Agreed, Disagreed, Single };
struct Vote {
    int32_t microvolts = 0;
    VoteKind kind = VoteKind::Single;
};
Vote vote(int32_t followed, bool otherFresh, int32_t other, bool haveLast, int32_t last);

/// The controller's law, shared by the controller and the voter.
int32_t controlOutput(int32_t setPointMicrovolts, int32_t pvMicrovolts);

/// The controller's set point; it applies from its next cycle.
struct VoterStatistics {
    uint32_t cycles = 0;
    int32_t lastPv = 0;
    int32_t lastMv = 0;
    uint32_t agreed = 0;     ///< Cycles on the mean of both samplers.
    uint32_t disagreed = 0;  ///< Cycles on which they disagreed; the nearer one was used.
    uint32_t single = 0;     ///< Cycles with only the followed sampler fresh.
    uint32_t failovers = 0;  ///< Times the followed sampler fell silent and the other was followed.
    uint32_t readBackErrors = 0;
    uint32_t errors = 0;
};

void setSetPoint(int32_t microvolts);
int32_t setPoint();

SamplerStatistics samplerStatistics();
ControllerStatistics controllerStatistics();
ActuatorStatistics actuatorStatistics();
VoterStatistics voterStatistics();

} // namespace plant
