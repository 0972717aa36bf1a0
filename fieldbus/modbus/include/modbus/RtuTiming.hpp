// The character timing of an RTU line ([SL] 2.5.1.1, 2.5.3).
//
// An RTU character is 11 bits on the wire: a start bit, 8 data bits, a parity
// bit and a stop bit, or two stop bits without parity ([SL] 2.5.1). Frames
// are separated by a silence of at least 3.5 character times (t3.5), and the
// characters of one frame by at most 1.5 (t1.5). Above 19200 baud the
// specification recommends fixed values, 750 us and 1750 us, because the
// computed ones become shorter than a UART's interrupt latency ([SL] 2.5.1.1,
// "Remark"). Some devices run 8N1 (10 bits) against the specification; the
// character format is a parameter so that such a line can still be timed.
#pragma once

#include <modbus/ModbusResult.hpp>

#include <stdint.h>

namespace modbus {

struct RtuTiming {
    /// Bits of a character as [SL] 2.5.1 defines it.
    static constexpr uint8_t kStandardCharacterBits = 11;
    /// The 8N1 format that some devices use against the specification.
    static constexpr uint8_t kMinCharacterBits = 10;
    static constexpr uint8_t kMaxCharacterBits = 12;
    /// Above this baud rate t1.5 and t3.5 are fixed ([SL] 2.5.1.1).
    static constexpr uint32_t kFixedTimingAboveBaud = 19200;
    static constexpr uint64_t kFixedT15Ns = 750000;
    static constexpr uint64_t kFixedT35Ns = 1750000;
    /// The baud rates a line may be configured with: from the slowest the
    /// specification mentions to well past any RS-485 UART of the boards.
    static constexpr uint32_t kMinBaud = 300;
    static constexpr uint32_t kMaxBaud = 4000000;

    // A default-constructed timing is that of the default line of [SL]
    // 2.5.1, 19200 baud with 11-bit characters, as make(19200) computes it
    // (a unit test holds the two together).

    /// The time one character takes on the wire.
    uint64_t characterNs = 572917;
    /// The longest silence allowed between two characters of a frame.
    uint64_t t15Ns = 859375;
    /// The silence that ends a frame and must precede the next one.
    uint64_t t35Ns = 2005209;

    /// The timing of a line at @p baud with @p characterBits bits per
    /// character, or InvalidConfiguration for a baud rate outside
    /// kMinBaud..kMaxBaud or a character format outside 10..12 bits.
    static ModbusResult<RtuTiming> make(uint32_t baud, uint8_t characterBits = kStandardCharacterBits);
};

} // namespace modbus
