#include <sja1000/BitTiming.hpp>
#include <sja1000/Sja1000Registers.hpp>

namespace sja1000 {

using dcos::Result;
using dcos::Status;

namespace {

// The distance between two sample points, in 1/1000 of the bit.
unsigned distance(unsigned a, unsigned b) { return a > b ? a - b : b - a; }

} // namespace

Result<BitTiming> BitTimingCalculator::forBitRate(uint32_t bitRate, uint32_t oscillatorHz)
{
    if (bitRate == 0 || oscillatorHz == 0) {
        return Status::InvalidArgument;
    }
    // The chip counts quanta of its CAN clock, oscillator / 2.
    const uint32_t canClockHz = oscillatorHz / 2;
    const unsigned wanted = recommendedSamplePoint(bitRate);
    BitTiming best{};
    unsigned bestError = ~0u;
    // Every prescaler that divides the clock into a whole number of quanta
    // per bit; of those, the one whose sample point comes nearest, and on a
    // tie the one with the most quanta (the finest resynchronisation).
    for (unsigned prescaler = 1; prescaler <= kMaxPrescaler; ++prescaler) {
        if (canClockHz % prescaler != 0) {
            continue;
        }
        const uint32_t quantumHz = canClockHz / prescaler;
        if (quantumHz % bitRate != 0) {
            continue;
        }
        const uint32_t quanta = quantumHz / bitRate;
        if (quanta < kMinQuantaPerBit || quanta > kMaxQuantaPerBit) {
            continue;
        }
        // The sample point falls after sync + TSEG1 quanta; pick TSEG2 so
        // that it lands nearest the wanted point, within both ranges.
        for (unsigned segment2 = kMinSegment2; segment2 <= kMaxSegment2; ++segment2) {
            const unsigned segment1 = quanta - 1 - segment2;
            if (segment1 < kMinSegment1 || segment1 > kMaxSegment1) {
                continue;
            }
            const unsigned samplePoint = 1000u * (1 + segment1) / quanta;
            const unsigned error = distance(samplePoint, wanted);
            if (error < bestError || (error == bestError && quanta > best.quantaPerBit)) {
                bestError = error;
                best.prescaler = static_cast<uint8_t>(prescaler);
                best.quantaPerBit = static_cast<uint8_t>(quanta);
                best.segment1 = static_cast<uint8_t>(segment1);
                best.segment2 = static_cast<uint8_t>(segment2);
                best.samplePointPermille = static_cast<uint16_t>(samplePoint);
            }
        }
    }
    if (best.quantaPerBit == 0) {
        return Status::InvalidArgument;
    }
    // The widest jump the registers allow without reaching past TSEG2.
    best.jumpWidth = static_cast<uint8_t>(best.segment2 < kMaxJumpWidth ? best.segment2 : kMaxJumpWidth);
    best.bitRate = bitRate;
    best.btr0 = static_cast<uint8_t>(((best.jumpWidth - 1u) << reg::kBtr0JumpWidthShift) | (best.prescaler - 1u));
    best.btr1 = static_cast<uint8_t>(((best.segment2 - 1u) << reg::kBtr1Segment2Shift) | (best.segment1 - 1u));
    return best;
}

Result<BitTiming> BitTimingCalculator::decode(uint8_t btr0, uint8_t btr1, uint32_t oscillatorHz)
{
    BitTiming timing{};
    timing.btr0 = btr0;
    timing.btr1 = btr1;
    timing.prescaler = static_cast<uint8_t>((btr0 & reg::kBtr0PrescalerMask) + 1u);
    timing.jumpWidth = static_cast<uint8_t>(((btr0 >> reg::kBtr0JumpWidthShift) & reg::kBtr0JumpWidthMask) + 1u);
    timing.segment1 = static_cast<uint8_t>((btr1 & reg::kBtr1Segment1Mask) + 1u);
    timing.segment2 = static_cast<uint8_t>(((btr1 >> reg::kBtr1Segment2Shift) & reg::kBtr1Segment2Mask) + 1u);
    timing.quantaPerBit = static_cast<uint8_t>(1u + timing.segment1 + timing.segment2);
    const uint32_t divisor = 2u * timing.prescaler * timing.quantaPerBit;
    if (oscillatorHz == 0 || oscillatorHz % divisor != 0) {
        return Status::InvalidArgument;
    }
    timing.bitRate = oscillatorHz / divisor;
    timing.samplePointPermille = static_cast<uint16_t>(1000u * (1u + timing.segment1) / timing.quantaPerBit);
    return timing;
}

} // namespace sja1000
