// The SJA1000's bus timing: from a bit rate to BTR0 and BTR1, and back.
//
// A CAN bit is divided into time quanta: one for synchronisation, TSEG1
// before the sample point and TSEG2 after it (ISO 11898-1, "bit timing").
// The SJA1000 makes the quantum from its clock, tq = 2 * tCLK * (BRP + 1),
// and takes TSEG1 of 1 to 16 quanta, TSEG2 of 1 to 8 and a jump width of 1
// to 4 (DS 6.5.1, 6.5.2). Every node of a bus must agree on the bit rate
// exactly; the sample point is where each node reads the bit, and the
// CiA's recommendations (which Linux's can_calc_bittiming also follows) put
// it at 87.5 % of the bit up to 500 kbit/s, 80 % up to 800 kbit/s and 75 %
// above, so that long buses have time for the signal to settle.
//
// Pure code without hardware: built for the host tests as for the firmware.
#pragma once

#include <dcos/Status.hpp>

#include <stdint.h>

namespace sja1000 {

/// The oscillator of the usual SJA1000 cards (and the default of Linux's
/// sja1000_isa driver); the chip's CAN clock is half of it.
constexpr uint32_t kDefaultOscillatorHz = 16'000'000;

/// The bit rates of CiA 301 (table "bit rates and bit timing"), in bit/s.
constexpr uint32_t kCiaBitRates[] = {10'000, 20'000, 50'000, 125'000, 250'000, 500'000, 800'000, 1'000'000};

/// One bit timing, in the chip's terms and in engineering terms.
struct BitTiming {
    uint8_t btr0 = 0;            ///< BRP and SJW, as written to BTR0.
    uint8_t btr1 = 0;            ///< TSEG1, TSEG2 and SAM, as written to BTR1.
    uint32_t bitRate = 0;        ///< Bits per second the registers give.
    uint16_t samplePointPermille = 0; ///< Where in the bit the bus is sampled, in 1/1000 of the bit.
    uint8_t quantaPerBit = 0;    ///< 1 + TSEG1 + TSEG2.
    uint8_t prescaler = 0;       ///< BRP + 1.
    uint8_t segment1 = 0;        ///< TSEG1 in quanta.
    uint8_t segment2 = 0;        ///< TSEG2 in quanta.
    uint8_t jumpWidth = 0;       ///< SJW in quanta.
};

class BitTimingCalculator {
public:
    static constexpr unsigned kMinSegment1 = 1;
    static constexpr unsigned kMaxSegment1 = 16;
    static constexpr unsigned kMinSegment2 = 1;
    static constexpr unsigned kMaxSegment2 = 8;
    static constexpr unsigned kMaxJumpWidth = 4;
    static constexpr unsigned kMaxPrescaler = 64;
    /// Fewer quanta cannot place a sample point usefully; more than 25 the registers cannot hold.
    static constexpr unsigned kMinQuantaPerBit = 8;
    static constexpr unsigned kMaxQuantaPerBit = 1 + kMaxSegment1 + kMaxSegment2;

    /// The CiA's sample point for @p bitRate, in 1/1000 of the bit.
    static constexpr uint16_t recommendedSamplePoint(uint32_t bitRate)
    {
        return bitRate > 800'000 ? 750 : bitRate > 500'000 ? 800 : 875;
    }

    /// The timing for exactly @p bitRate with the sample point nearest the
    /// CiA's, on a chip with @p oscillatorHz. InvalidArgument when no
    /// register setting gives the bit rate exactly (a node a little off
    /// the bus's rate fails only under load, so none is offered).
    static dcos::Result<BitTiming> forBitRate(uint32_t bitRate, uint32_t oscillatorHz = kDefaultOscillatorHz);

    /// What BTR0 and BTR1 mean on a chip with @p oscillatorHz; InvalidArgument
    /// when the bit rate is not a whole number of bits per second.
    static dcos::Result<BitTiming> decode(uint8_t btr0, uint8_t btr1, uint32_t oscillatorHz = kDefaultOscillatorHz);
};

} // namespace sja1000
