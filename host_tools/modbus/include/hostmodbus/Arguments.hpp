// The values dcos-modbus and dcos-modbus-sim take on their command lines:
// addresses, register and coil values, "address=value,value" lists and the
// serial line's settings. They come from the user, so every parser checks
// the whole text and says what it expected (host_tools/modbus/fuzz).
#pragma once

#include <hostmodbus/Result.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hostmodbus {

/// Quantity limits of [AP] 6.x, so a request the slave must refuse is
/// refused here already, with the limit named.
constexpr unsigned kMaxReadBits = 2000;      // 01, 02
constexpr unsigned kMaxReadRegisters = 125;  // 03, 04, the read part of 17
constexpr unsigned kMaxWriteBits = 1968;     // 0F
constexpr unsigned kMaxWriteRegisters = 123; // 10
constexpr unsigned kMaxReadWriteWriteRegisters = 121; // the write part of 17

/// An unsigned number in decimal or, with 0x, hexadecimal, at most @p max.
Result<uint32_t> parseUnsigned(std::string_view text, uint32_t max, std::string_view what);

/// A data address 0..65535 (the protocol's address, not a 4xxxx number).
Result<uint16_t> parseAddress(std::string_view text);

/// A register value: 0..65535, 0x0000..0xFFFF, or -32768..-1 written as
/// its two's complement.
Result<uint16_t> parseRegisterValue(std::string_view text);

/// A coil value: 1, 0, on, off, true or false.
Result<bool> parseBit(std::string_view text);

/// A slave address 1..247 ([SL] 2.2; broadcast is not offered, since a
/// tool that reports what the slave answered has nothing to report).
Result<uint8_t> parseSlaveAddress(std::string_view text);

/// "address=value,value,..." for register writes.
struct RegisterList {
    uint16_t address = 0;
    std::vector<uint16_t> values;
};
Result<RegisterList> parseRegisterList(std::string_view text, unsigned maxCount);

/// "address=bit,bit,..." for coil writes.
struct BitList {
    uint16_t address = 0;
    std::vector<bool> values;
};
Result<BitList> parseBitList(std::string_view text, unsigned maxCount);

/// "address:count" for the read part of 17.
struct Range {
    uint16_t address = 0;
    uint16_t count = 0;
};
Result<Range> parseRange(std::string_view text, unsigned maxCount);

/// Checks that @p count items from @p address stay within 0..65535.
Result<Range> checkRange(uint32_t address, uint32_t count, unsigned maxCount);

/// The parity as libmodbus takes it ('N', 'E', 'O') from N/E/O or
/// none/even/odd, in either case.
Result<char> parseParity(std::string_view text);

/// A baud rate the Linux serial drivers (and so libmodbus) can set; any
/// other would be replaced by 9600 in silence.
Result<int> checkBaudRate(long baud);

} // namespace hostmodbus
