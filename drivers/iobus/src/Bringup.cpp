// The bring-up sequence: docs/iobus/bringup-protocol.md is its contract.
#include <iobus/Bringup.hpp>

#include <iobus/AnalogScaling.hpp>
#include <iobus/LinearityFit.hpp>
#include <iobus/MfioClient.hpp>
#include <iobus/MfioRegisters.hpp>

#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/Version.hpp>

namespace iobus {

using dcos::Status;
using dcos::systemAgent;

namespace {

constexpr uint32_t kGainFactors[] = {1, 10, 100, 1000};

// Prints a value given in hundredths with two decimals, e.g. -0.02.
void printHundredths(runtime::CharacterSink& out, int32_t hundredths)
{
    const uint32_t magnitude = hundredths < 0 ? static_cast<uint32_t>(-int64_t{hundredths})
                                              : static_cast<uint32_t>(hundredths);
    runtime::format(out, "%s%lu.%02lu", hundredths < 0 ? "-" : "", static_cast<unsigned long>(magnitude / 100u),
                    static_cast<unsigned long>(magnitude % 100u));
}

// The noise of one sweep pooled over its points: every point's repeated
// conversions scatter around that point's own mean, so the within-point sums
// of squares add up to one estimate of the converter's noise variance with
// sum(n_i - 1) degrees of freedom. One estimate per sweep, with its degrees
// of freedom, lets the host judge the noise with a statistical test, where
// the largest of many small-sample deviations exceeds a limit by chance.
struct PooledNoise {
    int32_t deviationHundredths; ///< The pooled standard deviation, in hundredths of an LSB, rounded.
    uint32_t degreesOfFreedom;   ///< sum(n_i - 1) over the points.
    uint32_t samplesPerPoint;    ///< The fewest conversions of any point (every point's count when complete).
};

PooledNoise pooledNoise(const LinearityFit& fit)
{
    // Within-point sum of squares x 10^4: (n x sum(x^2) - sum(x)^2) x 10^4 / n,
    // divided before it is scaled so that it stays below 2^64 with 12-bit
    // codes up to 10^5 conversions a point.
    uint64_t squares = 0;
    uint32_t freedom = 0;
    uint32_t fewest = 0;
    for (size_t i = 0; i < fit.count(); ++i) {
        const LinearityFit::Point& p = fit.point(i);
        fewest = (i == 0 || p.samples < fewest) ? p.samples : fewest;
        if (p.samples < 2) {
            continue;
        }
        const uint64_t n = p.samples;
        const uint64_t spread = n * p.sumSquares - uint64_t{p.sum} * p.sum;
        squares += spread / n * 10000u + spread % n * 10000u / n;
        freedom += p.samples - 1u;
    }
    if (freedom == 0) {
        return PooledNoise{0, 0, fewest};
    }
    const uint64_t variance = (squares + freedom / 2u) / freedom;
    // Rounds the square root to the nearest hundredth: r + 1 when variance > r^2 + r.
    uint64_t root = integerSquareRoot(variance);
    if (variance - root * root > root) {
        ++root;
    }
    return PooledNoise{static_cast<int32_t>(root), freedom, fewest};
}

// Prints the firmware's release and build revision, each word kept to the
// characters a key=value field may hold, so the host can tell which firmware
// measured a board.
void printFirmware(runtime::CharacterSink& out)
{
    char revision[48];
    const char* text = dcos::buildRevision();
    size_t length = 0;
    for (; text != nullptr && text[length] != '\0' && length + 1 < sizeof revision; ++length) {
        const char c = text[length];
        const bool plain = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '.' ||
                           c == '-' || c == '_' || c == '+';
        revision[length] = plain ? c : '_';
    }
    revision[length] = '\0';
    runtime::format(out, "BRINGUP FIRMWARE version=%s revision=%s\r\n", dcos::versionString,
                    length == 0 ? "unknown" : revision);
}

Status setMode(dcos::ObjectId id, ConversionMode mode)
{
    uint32_t value = static_cast<uint32_t>(mode);
    return systemAgent.Control(id, MfioBoard::kSetMode, &value, sizeof value);
}

Status setFallback(dcos::ObjectId id, bool enable)
{
    uint32_t value = enable ? 1u : 0u;
    return systemAgent.Control(id, MfioBoard::kSetAutomaticFallback, &value, sizeof value);
}

// One walk: every output bit alone high (ones) or alone low (zeros).
unsigned walk(runtime::CharacterSink& out, dcos::ObjectId id, bool ones)
{
    uint16_t failedBits = 0;
    uint16_t firstWrote = 0;
    uint16_t firstRead = 0;
    bool failed = false;
    bool broken = false;
    for (unsigned bit = 0; bit < mfio::kDigitalBits; ++bit) {
        const uint16_t pattern = ones ? static_cast<uint16_t>(1u << bit) : static_cast<uint16_t>(~(1u << bit));
        const Status written = writeWord(id, channel::kDigitalOutputs, pattern);
        const dcos::Result<uint16_t> read = readWord(id, channel::kDigitalInputs);
        if (written != Status::Ok || !read.ok()) {
            broken = true;
            break;
        }
        const uint16_t difference = static_cast<uint16_t>(read.value() ^ pattern);
        if (difference != 0) {
            if (!failed) {
                firstWrote = pattern;
                firstRead = read.value();
            }
            failed = true;
            failedBits = static_cast<uint16_t>(failedBits | difference);
        }
    }
    (void)writeWord(id, channel::kDigitalOutputs, 0);
    const char* name = ones ? "walking-ones" : "walking-zeros";
    if (broken) {
        runtime::format(out, "BRINGUP DIO %s fail bits=0xffff wrote=0x0000 read=0x0000\r\n", name);
        return 1;
    }
    if (!failed) {
        runtime::format(out, "BRINGUP DIO %s ok\r\n", name);
        return 0;
    }
    runtime::format(out, "BRINGUP DIO %s fail bits=0x%04x wrote=0x%04x read=0x%04x\r\n", name, failedBits,
                    firstWrote, firstRead);
    return 1;
}

// Steps the DAC of one channel over the range one gain measures and prints
// the ADC line. Returns 1 when a conversion failed or the input did not
// follow the DAC (a stuck or dead channel), 0 otherwise.
unsigned measureChannel(runtime::CharacterSink& out, dcos::ObjectId id, unsigned input, uint32_t factor,
                        const BringupSettings& settings, LinearityFit& fit)
{
    fit.clear();
    const Gain gain = AnalogScaling::fromFactor(factor).value();
    bool broken = setGain(id, input, factor) != Status::Ok;
    // The largest DAC offset from 0 V whose ideal ADC code keeps the margin.
    const int32_t reach = (static_cast<int32_t>(mfio::kCodeZero) - static_cast<int32_t>(settings.marginCodes)) /
                          static_cast<int32_t>(factor);
    unsigned points = settings.maximumPoints;
    if (points > LinearityFit::kMaximumPoints) {
        points = LinearityFit::kMaximumPoints;
    }
    if (points > static_cast<unsigned>(2 * reach + 1)) {
        points = static_cast<unsigned>(2 * reach + 1);
    }
    if (points < 2) {
        points = 2;
    }
    uint32_t overranges = 0;
    for (unsigned step = 0; step < points && !broken; ++step) {
        // Symmetric steps from -reach to +reach, rounded away from zero alike on both sides.
        const int32_t numerator = static_cast<int32_t>(2 * step) - static_cast<int32_t>(points - 1);
        const int32_t scaled = numerator * reach;
        const int32_t denominator = static_cast<int32_t>(points - 1);
        const int32_t magnitude = ((scaled < 0 ? -scaled : scaled) + denominator / 2) / denominator;
        const int32_t offset = scaled < 0 ? -magnitude : magnitude;
        const uint16_t output = static_cast<uint16_t>(static_cast<int32_t>(mfio::kCodeZero) + offset);
        if (writeWord(id, channel::kAnalogOutput0 + input, output) != Status::Ok) {
            broken = true;
            break;
        }
        fit.beginPoint(output, AnalogScaling::loopbackAdcCode(output, gain).code);
        for (unsigned sample = 0; sample < settings.samplesPerPoint; ++sample) {
            const dcos::Result<uint16_t> word = readAnalogInput(id, input);
            if (!word.ok()) {
                broken = true;
                break;
            }
            fit.addSample(static_cast<uint16_t>(word.value() & mfio::kAdcDataCodeMask));
            overranges += (word.value() & mfio::kAdcDataOverrange) != 0 ? 1u : 0u;
        }
    }
    (void)writeWord(id, channel::kAnalogOutput0 + input, mfio::kCodeZero);

    runtime::format(out, "BRINGUP ADC channel=%u gain=%lu offset_lsb=", input, static_cast<unsigned long>(factor));
    printHundredths(out, fit.offsetHundredths());
    runtime::format(out, " gain_error_pct=");
    printHundredths(out, fit.gainErrorHundredthsPercent());
    runtime::format(out, " max_error_lsb=");
    printHundredths(out, fit.maximumErrorHundredths());
    runtime::format(out, " noise_lsb=");
    printHundredths(out, fit.noiseHundredths());
    const PooledNoise pooled = pooledNoise(fit);
    runtime::format(out, " noise_pooled_lsb=");
    printHundredths(out, pooled.deviationHundredths);
    runtime::format(out, " noise_dof=%lu samples=%lu", static_cast<unsigned long>(pooled.degreesOfFreedom),
                    static_cast<unsigned long>(pooled.samplesPerPoint));
    runtime::format(out, " overrange=%lu points=", static_cast<unsigned long>(overranges));
    for (size_t i = 0; i < fit.count(); ++i) {
        const int32_t mean = fit.meanTenths(i);
        runtime::format(out, "%s%u:%ld.%ld", i == 0 ? "" : ",", static_cast<unsigned>(fit.point(i).output),
                        static_cast<long>(mean / 10), static_cast<long>(mean % 10));
    }
    runtime::format(out, "\r\n");
    // A healthy input follows the DAC over its whole span; one that moves
    // less than half of it is stuck or dead.
    const bool stuck = fit.measuredSpanHundredths() < fit.idealSpan() * 50;
    return broken || stuck ? 1u : 0u;
}

unsigned measureInterrupts(runtime::CharacterSink& out, dcos::ObjectId id, const BringupSettings& settings)
{
    constexpr unsigned kInput = 0;
    (void)setGain(id, kInput, 1);
    (void)writeWord(id, channel::kAnalogOutput0 + kInput, mfio::kCodeZero);
    (void)setFallback(id, false);
    const bool modeSet = setMode(id, ConversionMode::Interrupt) == Status::Ok;
    unsigned delivered = 0;
    uint64_t latencyMinimum = ~uint64_t{0};
    uint64_t latencyMaximum = 0;
    bool broken = !modeSet;
    // An event left over from an earlier conversion must not count.
    (void)dcos::taskAgent.ReceiveEvent(MfioBoard::kDefaultConversionEvent, dcos::EventWait::Any, dcos::kPoll);
    for (unsigned i = 0; i < settings.interruptConversions && !broken; ++i) {
        uint16_t word = 0;
        const dcos::Result<size_t> started =
            systemAgent.Read(id, channel::kAnalogInput0 + kInput, &word, sizeof word);
        if (!started.ok()) {
            broken = true;
            break;
        }
        if (started.value() != 0) {
            continue; // A result latched earlier; this Read did not start a conversion.
        }
        const dcos::Result<uint32_t> event = dcos::taskAgent.ReceiveEvent(
            MfioBoard::kDefaultConversionEvent, dcos::EventWait::Any, settings.interruptTimeoutNs);
        if (event.ok()) {
            ++delivered;
            BoardStatistics statistics{};
            if (systemAgent.Control(id, MfioBoard::kGetStatistics, &statistics, sizeof statistics) == Status::Ok) {
                const uint64_t expected = statistics.lastStartNs + mfio::kNominalConversionNs;
                const uint64_t latency =
                    statistics.lastInterruptNs > expected ? statistics.lastInterruptNs - expected : 0;
                latencyMinimum = latency < latencyMinimum ? latency : latencyMinimum;
                latencyMaximum = latency > latencyMaximum ? latency : latencyMaximum;
            }
        }
        // Collects the result: latched by the interrupt, or polled after the bound.
        const dcos::Result<size_t> collected =
            systemAgent.Read(id, channel::kAnalogInput0 + kInput, &word, sizeof word);
        if (!collected.ok()) {
            broken = true;
        }
    }
    (void)setFallback(id, true);
    if (delivered == 0) {
        latencyMinimum = 0;
    }
    runtime::format(out, "BRINGUP IRQ delivered=%u requested=%u latency_min_ns=%llu latency_max_ns=%llu\r\n",
                    delivered, settings.interruptConversions, static_cast<unsigned long long>(latencyMinimum),
                    static_cast<unsigned long long>(latencyMaximum));
    return broken || delivered < settings.interruptConversions ? 1u : 0u;
}

} // namespace

unsigned runBringupSteps(runtime::CharacterSink& out, dcos::ObjectId id, const BringupSettings& settings)
{
    printFirmware(out);
    unsigned failures = 0;
    failures += walk(out, id, true);
    failures += walk(out, id, false);

    (void)setMode(id, ConversionMode::Polled);
    static LinearityFit fit; // Static: too large for the shell task's stack frame alongside the console.
    for (unsigned input = 0; input < mfio::kAnalogInputs; ++input) {
        for (const uint32_t factor : kGainFactors) {
            failures += measureChannel(out, id, input, factor, settings, fit);
        }
        (void)setGain(id, input, 1);
    }
    failures += measureInterrupts(out, id, settings);
    (void)setMode(id, ConversionMode::Interrupt);
    return failures;
}

} // namespace iobus
