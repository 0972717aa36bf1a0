// The CRC-16 of Modbus RTU frames ([SL] 2.5.1.2, 6.2.2).
//
// Polynomial 0x8005 processed least significant bit first (0xA001 reflected),
// initial value 0xFFFF, no final XOR. The CRC covers the address and the PDU,
// and goes on the wire low byte first, which sets it apart from every other
// 16-bit field of Modbus. The computation uses a 256-entry table built by the
// compiler, one look-up per byte, because a slave must check a frame within
// the 1.5- to 3.5-character window the line gives it.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace modbus {

class Crc16 {
public:
    /// The initial value of the register ([SL] 6.2.2).
    static constexpr uint16_t kInitial = 0xFFFF;
    /// The generator polynomial, bit-reversed for LSB-first processing.
    static constexpr uint16_t kPolynomial = 0xA001;

    /// The CRC of @p length bytes at @p bytes.
    static uint16_t compute(const uint8_t* bytes, size_t length) { return update(kInitial, bytes, length); }

    /// Continues the CRC @p crc over @p length more bytes, so a frame can be
    /// checked as it arrives.
    static uint16_t update(uint16_t crc, const uint8_t* bytes, size_t length);

    /// Whether the last two of @p length bytes are the CRC of the others, low
    /// byte first; false for fewer than three bytes.
    static bool check(const uint8_t* frame, size_t length);

    /// Appends the CRC of the @p length bytes at @p frame to them, low byte
    /// first; the buffer must hold @p length + 2 bytes.
    static void append(uint8_t* frame, size_t length);
};

} // namespace modbus
