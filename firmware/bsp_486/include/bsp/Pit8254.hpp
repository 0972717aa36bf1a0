// Driver for counter 0 of the Intel 8254 programmable interval timer, the
// system tick of a PC-compatible board.
//
// Register and bit names follow the Intel 8254 datasheet (order number
// 231164), section "Control Word Format" and the mode descriptions.
#pragma once

#include <stdint.h>

#include <arch_x86/IoWindow.hpp>
#include <dcos/Status.hpp>

namespace bsp {

class Pit8254 {
public:
    /// The input clock of every counter on a PC: 14.31818 MHz / 12.
    static constexpr uint32_t inputClockHz = 1193182;

    // Port offsets within the chip's four-port window.
    static constexpr uint8_t counter0Register = 0;
    static constexpr uint8_t controlWordRegister = 3;

    // Control word fields.
    static constexpr uint8_t selectCounter0 = 0u << 6;        // SC1 SC0
    static constexpr uint8_t accessLowThenHigh = 3u << 4;     // RW1 RW0
    static constexpr uint8_t modeRateGenerator = 2u << 1;     // M2 M1 M0 = mode 2
    static constexpr uint8_t binaryCounting = 0u;             // BCD = 0
    static constexpr uint8_t latchCounter0 = 0x00;            // counter latch command

    /// Tick rates the system accepts. The divisor is 16 bits wide, so the
    /// slowest rate is 1193182 / 65535 = 18.2 Hz; above 10 kHz tick
    /// handling eats too much of a 486's time.
    static constexpr uint32_t minimumRateHz = 19;
    static constexpr uint32_t maximumRateHz = 10000;

    explicit Pit8254(arch_x86::IoWindow window) : window_(window) {}

    /// The 16-bit divisor closest to the requested rate.
    static constexpr uint16_t divisorFor(uint32_t rateHz)
    {
        return static_cast<uint16_t>((inputClockHz + rateHz / 2) / rateHz);
    }
    static_assert((inputClockHz + minimumRateHz / 2) / minimumRateHz <= 0xFFFF,
                  "the slowest rate's divisor must fit the 16-bit counter");

    /// Starts counter 0 as a rate generator at rateHz, or refuses a rate
    /// outside [minimumRateHz, maximumRateHz] with InvalidArgument.
    /// @p shortenBy counts less per period than the rate's divisor, while
    /// divisor() and tickPeriodNanoseconds() still say the rate's: the
    /// lab's model of a crystal that runs fast (the crystal_ppm= option of
    /// Board.hpp), since an emulated 8254 counts at exactly 1,193,182 Hz.
    /// InvalidArgument when it would leave fewer than half the counts.
    dcos::Status start(uint32_t rateHz, uint16_t shortenBy = 0);

    /// The rate that was asked for.
    uint32_t requestedRateHz() const { return requestedRateHz_; }
    /// The divisor of the rate asked for.
    uint16_t divisor() const { return divisor_; }
    /// The divisor programmed into the counter: divisor() less start's shortenBy.
    uint16_t programmedDivisor() const { return programmed_; }
    /// The exact tick period the divisor gives, in nanoseconds (rounded).
    uint64_t tickPeriodNanoseconds() const;
    /// Reads the current count of counter 0 (counts down to 1 each period).
    uint16_t readCount() const;

private:
    arch_x86::IoWindow window_;
    uint32_t requestedRateHz_ = 0;
    uint16_t divisor_ = 0;
    uint16_t programmed_ = 0;
};

} // namespace bsp
