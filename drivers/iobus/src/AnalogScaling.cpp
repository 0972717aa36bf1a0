#include <iobus/AnalogScaling.hpp>

#include <iobus/MfioRegisters.hpp>

namespace iobus {

namespace {

// A code step is 20 V / 4096 = 1 250 000 uV / 256 (before the amplifier's gain).
constexpr int64_t kStepNumerator = 1250000;
constexpr int64_t kStepDenominator = 256;
constexpr int32_t kCodeZero = mfio::kCodeZero;
constexpr int32_t kCodeMaximum = mfio::kCodeMaximum;

// Divides rounding half away from zero; denominator > 0.
int64_t divideRounded(int64_t numerator, int64_t denominator)
{
    if (numerator >= 0) {
        return (numerator + denominator / 2) / denominator;
    }
    return -((-numerator + denominator / 2) / denominator);
}

AnalogCode clampCode(int64_t code)
{
    if (code < 0) {
        return {0, true};
    }
    if (code > kCodeMaximum) {
        return {static_cast<uint16_t>(kCodeMaximum), true};
    }
    return {static_cast<uint16_t>(code), false};
}

} // namespace

uint32_t AnalogScaling::factor(Gain gain)
{
    switch (gain) {
    case Gain::X1: return 1;
    case Gain::X10: return 10;
    case Gain::X100: return 100;
    case Gain::X1000: return 1000;
    }
    return 1;
}

dcos::Result<Gain> AnalogScaling::fromFactor(uint32_t factor)
{
    switch (factor) {
    case 1: return Gain::X1;
    case 10: return Gain::X10;
    case 100: return Gain::X100;
    case 1000: return Gain::X1000;
    default: return dcos::Status::InvalidArgument;
    }
}

int32_t AnalogScaling::inputRangeMicrovolts(Gain gain)
{
    return kFullScaleMicrovolts / static_cast<int32_t>(factor(gain));
}

AnalogValue AnalogScaling::adcToMicrovolts(uint16_t data, Gain gain)
{
    const int32_t code = data & mfio::kAdcDataCodeMask;
    const int64_t numerator = int64_t{code - kCodeZero} * kStepNumerator;
    const int64_t denominator = kStepDenominator * static_cast<int64_t>(factor(gain));
    const bool overrange = (data & mfio::kAdcDataOverrange) != 0 || code == 0 || code == kCodeMaximum;
    return {static_cast<int32_t>(divideRounded(numerator, denominator)), overrange};
}

AnalogCode AnalogScaling::microvoltsToAdc(int32_t microvolts, Gain gain)
{
    const int64_t numerator = int64_t{microvolts} * static_cast<int64_t>(factor(gain)) * kStepDenominator;
    return clampCode(divideRounded(numerator, kStepNumerator) + kCodeZero);
}

int32_t AnalogScaling::dacToMicrovolts(uint16_t code)
{
    const int32_t value = code & mfio::kDacCodeMask;
    return static_cast<int32_t>(divideRounded(int64_t{value - kCodeZero} * kStepNumerator, kStepDenominator));
}

AnalogCode AnalogScaling::microvoltsToDac(int32_t microvolts)
{
    return clampCode(divideRounded(int64_t{microvolts} * kStepDenominator, kStepNumerator) + kCodeZero);
}

AnalogCode AnalogScaling::loopbackAdcCode(uint16_t dacCode, Gain gain)
{
    const int64_t offset = int64_t{static_cast<int32_t>(dacCode & mfio::kDacCodeMask) - kCodeZero};
    return clampCode(kCodeZero + offset * static_cast<int64_t>(factor(gain)));
}

} // namespace iobus
