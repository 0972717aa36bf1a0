// The frequency multiplier (seed 9.4.1, Test Case 1, Fig. 9.5): what its
// function blocks share with each other and with the console command.
//
// Two square waves A and B of the source frequency f, B behind A by a
// phase shift, are combined by XOR into Y, a wave of 2f whose duty cycle
// is the shift over 180 degrees: Y is high while exactly one source is.
// Every edge is a whole number of system ticks after the last, so the
// node can only make the frequencies and shifts that divide its tick;
// checkSettings says which, and why not.
#pragma once

#include <dcos/MessagePortAgent.hpp>
#include <dcos/ObjectId.hpp>

#include <stddef.h>
#include <stdint.h>

namespace freqmul {

/// The tick the application declares: 8 per source period at 1 kHz, so a
/// quarter-period shift (90 degrees) at 1 kHz is two ticks and 45 degrees one.
constexpr uint32_t kTickRateHz = 8000;

/// The waves at boot: 1 kHz sources, 90 degrees apart (Y at 2 kHz, 50 %).
constexpr uint32_t kDefaultFrequencyHz = 1000;
constexpr uint32_t kDefaultShiftDegrees = 90;

/// The digital outputs the DO block drives, one word per change.
constexpr uint16_t kBitA = 1u << 0; ///< DO0: source A.
constexpr uint16_t kBitB = 1u << 1; ///< DO1: source B, shifted.
constexpr uint16_t kBitY = 1u << 2; ///< DO2: Y = A XOR B.
constexpr uint16_t kWaveBits = kBitA | kBitB | kBitY;

/// Why a frequency and shift cannot be made.
enum class SettingsError : uint8_t {
    None,
    FrequencyZero,      ///< f = 0 Hz.
    HalfPeriodNotWhole, ///< The tick rate is not a multiple of 2f.
    HalfPeriodTooShort, ///< Half a period is one tick: no room for a shift between the edges.
    ShiftOutOfRange,    ///< The shift is not from 1 to 179 degrees (0 and 180 make Y constant).
    ShiftNotWhole,      ///< The shift is not a whole number of ticks.
};

/// The waves in ticks. A toggles every halfPeriodTicks; B follows each
/// edge of A after shiftTicks; Y is high for shiftTicks of every halfPeriodTicks.
struct WaveSettings {
    uint32_t frequencyHz = 0;
    uint32_t shiftDegrees = 0;
    uint32_t halfPeriodTicks = 0;
    uint32_t shiftTicks = 0;
};

struct SettingsCheck {
    SettingsError error = SettingsError::None;
    WaveSettings settings;
    /// With ShiftNotWhole: the shifts that can be made are multiples of this.
    uint32_t shiftStepDegrees = 0;
};

constexpr uint32_t greatestCommonDivisor(uint32_t a, uint32_t b)
{
    while (b != 0) {
        const uint32_t rest = a % b;
        a = b;
        b = rest;
    }
    return a;
}

/// The waves for source frequency @p frequencyHz and phase shift
/// @p shiftDegrees on a node ticking at @p tickRateHz, or why they cannot be made.
constexpr SettingsCheck checkSettings(uint32_t tickRateHz, uint32_t frequencyHz, uint32_t shiftDegrees)
{
    SettingsCheck check;
    if (frequencyHz == 0) {
        check.error = SettingsError::FrequencyZero;
        return check;
    }
    if (tickRateHz % (2 * uint64_t{frequencyHz}) != 0) {
        check.error = SettingsError::HalfPeriodNotWhole;
        return check;
    }
    const uint32_t halfPeriodTicks = tickRateHz / (2 * frequencyHz);
    if (halfPeriodTicks < 2) {
        check.error = SettingsError::HalfPeriodTooShort;
        return check;
    }
    if (shiftDegrees == 0 || shiftDegrees >= 180) {
        check.error = SettingsError::ShiftOutOfRange;
        return check;
    }
    // shiftTicks = halfPeriodTicks * shiftDegrees / 180 must be whole.
    if ((uint64_t{halfPeriodTicks} * shiftDegrees) % 180 != 0) {
        check.error = SettingsError::ShiftNotWhole;
        check.shiftStepDegrees = 180 / greatestCommonDivisor(halfPeriodTicks, 180);
        return check;
    }
    check.settings = WaveSettings{frequencyHz, shiftDegrees, halfPeriodTicks,
                                  static_cast<uint32_t>(uint64_t{halfPeriodTicks} * shiftDegrees / 180)};
    return check;
}

static_assert(checkSettings(kTickRateHz, kDefaultFrequencyHz, kDefaultShiftDegrees).error == SettingsError::None,
              "the waves at boot must be exact in ticks");
static_assert(checkSettings(kTickRateHz, 1000, 90).settings.shiftTicks == 2);
static_assert(checkSettings(kTickRateHz, 1000, 45).settings.shiftTicks == 1);
static_assert(checkSettings(kTickRateHz, 1000, 30).shiftStepDegrees == 45);
static_assert(checkSettings(kTickRateHz, 3000, 90).error == SettingsError::HalfPeriodNotWhole);
static_assert(checkSettings(kTickRateHz, 4000, 90).error == SettingsError::HalfPeriodTooShort);

/// What the DO block and the checker have seen since boot.
struct CheckerStatistics {
    uint32_t doWrites = 0;            ///< DO words written.
    uint32_t doWriteErrors = 0;       ///< Writes the board refused.
    uint32_t samples = 0;             ///< DI words the checker read, one per DO write.
    uint32_t edges[3] = {};           ///< Changes of DI bit 0 (A), 1 (B) and 2 (Y).
    uint32_t xorMismatches = 0;       ///< Samples with DI(Y) != DI(A) XOR DI(B).
    uint32_t loopbackMismatches = 0;  ///< Samples whose DI bits differ from the DO word just written.
    uint32_t readErrors = 0;          ///< DI reads the board refused.
};

/// The state the console shows, guarded by the semaphore freqmul.lock.
struct SharedState {
    WaveSettings applied;     ///< The waves E_CYCLE runs now.
    uint32_t generation = 0;  ///< Counts the settings E_CYCLE has applied, the boot's included.
    uint32_t rejected = 0;    ///< Control messages E_CYCLE refused (settings it cannot make).
    uint32_t boardStatus = 0; ///< The dcos::Status of installing and opening the I/O board.
    CheckerStatistics checker;
};

/// Takes a copy of the shared state; false when the lock could not be taken.
bool readSharedState(SharedState& copy);

/// Asks E_CYCLE to run new waves (already checked by the caller with
/// checkSettings) and waits until it has: the old waves have then stopped
/// and the new ones start half a source period later. Fails with
/// InvalidArgument when E_CYCLE refused them, Timeout when it did not
/// answer within 100 ms, or the status of the message port or task agent.
dcos::Status requestSettings(uint32_t frequencyHz, uint32_t shiftDegrees);

// Message layout shared by every block: up to four 32-bit words, least
// significant byte first, so that a block could move to another node
// without a change of format.
constexpr dcos::Message makeMessage(uint32_t word0, uint32_t word1 = 0, uint32_t word2 = 0, uint32_t word3 = 0)
{
    dcos::Message message{};
    const uint32_t words[4] = {word0, word1, word2, word3};
    for (size_t i = 0; i < dcos::kMessageSize; ++i) {
        message.bytes[i] = static_cast<uint8_t>(words[i / 4] >> (8 * (i % 4)));
    }
    return message;
}

constexpr uint32_t messageWord(const dcos::Message& message, unsigned index)
{
    uint32_t word = 0;
    for (unsigned i = 0; i < 4; ++i) {
        word |= static_cast<uint32_t>(message.bytes[4 * index + i]) << (8 * i);
    }
    return word;
}

static_assert(messageWord(makeMessage(1, 0x12345678, 3, 0xFFFFFFFF), 1) == 0x12345678);

} // namespace freqmul
