// Ends the emulator with a status through QEMU's isa-debug-exit device.
//
// The board definition (tests_renode/boards/*.json) places the device at
// port 0xF4; a write of v makes QEMU exit with status (v << 1) | 1. The
// values match EXIT_PASS, EXIT_FAIL and EXIT_PANIC in dcoslab/board.py.
#pragma once

#include <stdint.h>

namespace target_test {

constexpr uint16_t debugExitPort = 0xF4;
constexpr uint8_t exitPass = 0x10;
constexpr uint8_t exitFail = 0x11;
constexpr uint8_t exitPanic = 0x7F;

[[noreturn]] void exitEmulator(uint8_t code);

} // namespace target_test
