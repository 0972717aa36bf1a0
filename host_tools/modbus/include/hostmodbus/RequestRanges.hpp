// Which addresses a request PDU touches, read by dcos-modbus-sim from what
// a master sent, so that a request into a gap of the register map is
// refused (libmodbus's mapping only knows one span per table).
#pragma once

#include <hostmodbus/SimulatorConfig.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hostmodbus {

struct TableRange {
    Table table = Table::Coil;
    uint32_t address = 0;
    uint32_t count = 0;
};

/// How much of a request frame (address, PDU, CRC) has arrived, by the
/// lengths its function code implies. libmodbus's modbus_receive() frames
/// requests the same way but knows nothing of 2B, whose request it cuts
/// short; dcos-modbus-sim frames requests here instead and hands whole ones
/// to modbus_reply().
struct RequestScan {
    /// Unknown: the function gives no length; the frame ends where the line
    /// falls silent ([SL] 2.5.1.1's t3.5).
    enum class State { NeedMore, Complete, Unknown } state = State::NeedMore;
    size_t length = 0;
};
RequestScan scanRequest(const uint8_t* bytes, size_t size);

/// The ranges the request PDU @p pdu (function code first) reads or
/// writes: one for 01-06, 0F, 10 and 16, two for 17. Empty for any other
/// function, and for a PDU too short for its function.
std::vector<TableRange> requestRanges(const uint8_t* pdu, size_t size);

/// The exception a slave must answer @p pdu with before its addresses are
/// looked at ([AP] Figures 11-19: the function, then the quantity): 01 for
/// a function dcos-modbus-sim does not serve, 03 for a quantity out of
/// range, a byte count that disagrees with it or a coil value other than
/// 0000/FF00; zero when the request passes. The simulator sends these
/// itself, so its count of exceptions is exact whatever libmodbus does.
uint8_t requestException(const uint8_t* pdu, size_t size);

} // namespace hostmodbus
