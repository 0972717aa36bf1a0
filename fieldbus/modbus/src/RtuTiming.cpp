#include <modbus/RtuTiming.hpp>

namespace modbus {

namespace {

constexpr uint64_t kNsPerSecond = 1000000000;

// Rounded up, so that a silence the specification calls too long is never
// measured as just long enough.
uint64_t ceilDivide(uint64_t dividend, uint64_t divisor)
{
    return (dividend + divisor - 1) / divisor;
}

} // namespace

ModbusResult<RtuTiming> RtuTiming::make(uint32_t baud, uint8_t characterBits)
{
    if (baud < kMinBaud || baud > kMaxBaud || characterBits < kMinCharacterBits || characterBits > kMaxCharacterBits) {
        return ModbusError::InvalidConfiguration;
    }
    RtuTiming timing;
    const uint64_t bitsNs = characterBits * kNsPerSecond;
    timing.characterNs = ceilDivide(bitsNs, baud);
    if (baud > kFixedTimingAboveBaud) {
        timing.t15Ns = kFixedT15Ns;
        timing.t35Ns = kFixedT35Ns;
    } else {
        timing.t15Ns = ceilDivide(bitsNs * 3, 2ull * baud);
        timing.t35Ns = ceilDivide(bitsNs * 7, 2ull * baud);
    }
    return timing;
}

} // namespace modbus
