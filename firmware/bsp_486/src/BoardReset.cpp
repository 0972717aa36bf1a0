#include <bsp/BoardReset.hpp>

#include <arch_x86/PortIo.hpp>

namespace bsp {

namespace {

// The 8042's status and command port, and the status bit that says its
// input buffer still holds a byte the controller has not taken (IBM PC/AT
// Technical Reference, "Keyboard controller status register", bit 1).
constexpr uint16_t kKeyboardControllerCommand = 0x64;
constexpr uint8_t kInputBufferFull = 0x02;
constexpr uint8_t kPulseResetLine = 0xFE;

} // namespace

void resetBoard()
{
    asm volatile("cli");
    for (unsigned poll = 0; poll < 100000 && (arch_x86::portRead8(kKeyboardControllerCommand) & kInputBufferFull) != 0;
         ++poll) {
    }
    arch_x86::portWrite8(kKeyboardControllerCommand, kPulseResetLine);
    for (;;) {
        asm volatile("hlt");
    }
}

} // namespace bsp
