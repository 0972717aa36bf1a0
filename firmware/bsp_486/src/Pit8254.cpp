#include <bsp/Pit8254.hpp>

namespace bsp {

dcos::Status Pit8254::start(uint32_t rateHz, uint16_t shortenBy)
{
    if (rateHz < minimumRateHz || rateHz > maximumRateHz || shortenBy > divisorFor(rateHz) / 2) {
        return dcos::Status::InvalidArgument;
    }
    requestedRateHz_ = rateHz;
    divisor_ = divisorFor(rateHz);
    programmed_ = static_cast<uint16_t>(divisor_ - shortenBy);
    window_.write8(controlWordRegister, selectCounter0 | accessLowThenHigh | modeRateGenerator | binaryCounting);
    window_.write8(counter0Register, static_cast<uint8_t>(programmed_ & 0xFF));
    window_.write8(counter0Register, static_cast<uint8_t>(programmed_ >> 8));
    return dcos::Status::Ok;
}

uint64_t Pit8254::tickPeriodNanoseconds() const
{
    return (uint64_t{divisor_} * 1000000000ull + inputClockHz / 2) / inputClockHz;
}

uint16_t Pit8254::readCount() const
{
    window_.write8(controlWordRegister, latchCounter0);
    const uint8_t low = window_.read8(counter0Register);
    const uint8_t high = window_.read8(counter0Register);
    return static_cast<uint16_t>(low | (high << 8));
}

} // namespace bsp
