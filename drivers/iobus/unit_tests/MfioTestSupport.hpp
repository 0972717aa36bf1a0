// Shared helpers of the iobus host tests: port addresses of a board at
// 0x300 and access records for the recording port mock.
#pragma once

#include <iobus/MfioRegisters.hpp>

#include "../../../firmware/arch_x86/unit_tests/PortIoMock.hpp"

#include <cstdint>

namespace iobus_test {

constexpr uint16_t kBase = 0x300;
constexpr uint16_t port(uint16_t offset) { return static_cast<uint16_t>(kBase + offset); }

inline port_io_mock::Access in16(uint16_t offset, uint16_t value) { return {false, port(offset), value, 16}; }
inline port_io_mock::Access out16(uint16_t offset, uint16_t value) { return {true, port(offset), value, 16}; }

/// Makes the next probe find the board (ID, then REVISION 1.0).
inline void answerProbe()
{
    port_io_mock::queueRead(port(iobus::mfio::kIdRegister), iobus::mfio::kBoardId);
    port_io_mock::queueRead(port(iobus::mfio::kRevisionRegister), 0x0100);
}

} // namespace iobus_test
