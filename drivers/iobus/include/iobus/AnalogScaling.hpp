// Engineering units for the multi-function I/O board: codes <-> microvolts.
//
// This layer is separate from the driver, which deals only in raw 12-bit
// codes, so that the function block runtime (and host tools) can scale
// readings without touching hardware. The formulas are those of
// docs/iobus/mfio-register-map.md, "Analog scaling":
//
//     DAC:  V = (code - 2048) x 20 V / 4096
//     ADC:  code = round((Vin x gain + 10 V) x 4096 / 20 V), clamped to 0..4095
//
// The firmware has no floating point, so voltages are int32_t microvolts
// (+-10 V is +-10 000 000 uV) and every division rounds half away from zero.
// One ADC step is 4882.8125 uV / gain, so at gain 1000 a code converts to
// the nearest whole microvolt (about 4.9 uV per step).
#pragma once

#include <dcos/Status.hpp>

#include <stdint.h>

namespace iobus {

/// The programmable amplifier settings of an analog input (map row `GAIN`).
enum class Gain : uint8_t {
    X1 = 0,    ///< ×1: +-10 V full scale.
    X10 = 1,   ///< ×10: +-1 V.
    X100 = 2,  ///< ×100: +-100 mV.
    X1000 = 3, ///< ×1000: +-10 mV.
};

/// A reading in engineering units.
struct AnalogValue {
    int32_t microvolts; ///< The voltage, in microvolts.
    bool overrange;     ///< The converter saturated: the true value is at or beyond microvolts.
};

/// A code computed from a voltage.
struct AnalogCode {
    uint16_t code;  ///< The 12-bit code, 0..4095.
    bool saturated; ///< The voltage was outside the range and the code is clamped.
};

/// Conversions between codes and microvolts; every function is integer
/// arithmetic in bounded time.
class AnalogScaling {
public:
    /// Full scale of the converter and the DACs: 10 V.
    static constexpr int32_t kFullScaleMicrovolts = 10000000;

    /// The amplification factor of @p gain: 1, 10, 100 or 1000.
    static uint32_t factor(Gain gain);

    /// The gain whose factor is @p factor; InvalidArgument unless it is 1, 10, 100 or 1000.
    static dcos::Result<Gain> fromFactor(uint32_t factor);

    /// The largest input magnitude @p gain measures without saturating, in microvolts.
    static int32_t inputRangeMicrovolts(Gain gain);

    /// The input voltage (before the amplifier) that an ADC result stands for.
    ///
    /// @p data may be the whole `ADC_DATA` word: bits 11:0 are the code and
    /// bit 15 the board's overrange flag. A code of 0 or 4095 is also
    /// reported as overrange, since the input may lie beyond it.
    static AnalogValue adcToMicrovolts(uint16_t data, Gain gain);

    /// The ADC code an ideal board reads for @p microvolts at the input.
    static AnalogCode microvoltsToAdc(int32_t microvolts, Gain gain);

    /// The output voltage of a DAC code (bits 11:0 of @p code).
    static int32_t dacToMicrovolts(uint16_t code);

    /// The DAC code nearest to @p microvolts, clamped to the DAC's range.
    static AnalogCode microvoltsToDac(int32_t microvolts);

    /// The ideal ADC code at @p gain for a DAC code looped back to the same
    /// channel: 2048 + (dac - 2048) x gain, clamped.
    static AnalogCode loopbackAdcCode(uint16_t dacCode, Gain gain);
};

} // namespace iobus
