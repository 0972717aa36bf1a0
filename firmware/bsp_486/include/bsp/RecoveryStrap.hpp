// The board's recovery strap: a jumper (or a line from a service adapter
// such as an MCP2221A, docs/guide/flashing.md) that sends the board into
// the stage loader's recovery at its next start, whatever image its card
// holds. The stage loader reads it before it looks at the card's boot
// state, so a node whose image hangs at boot can always be flashed again.
//
// Like the jumper and DIP-switch read-back ports of ISA single-board
// computers, the ISA 486 board reads its jumper block on one I/O port.
// Every jumper is active low: a fitted jumper (or a line driven low) reads
// 0, an open one reads 1. A board without the jumper block reads the
// floating ISA bus, 0xFF, which is "no jumper fitted": no strap.
//
// Header only: the stage loader uses it without a source file of its own
// (host unit tests read the port through the recording mock).
#pragma once

#include <stdint.h>

#include <arch_x86/PortIo.hpp>

namespace bsp {

/// The jumper block's read-back port. 0x2C0 lies between the CAN card's two
/// channels (0x280 to 0x2BF) and COM4's place (0x2E8), where no PC/AT
/// device sits. The lab's model is `lab-gpio-header`
/// (tests_renode/models/isa_gpio_header.c).
constexpr uint16_t kJumperPort = 0x2C0;

/// Bit 0 of the jumper port: the recovery strap, active low.
constexpr uint8_t kRecoveryStrapBit = 0x01;

/// Bit 1 of the jumper port: the level of the board's reset line as the
/// header sees it (1 released). Informative only: while the line is low
/// the processor does not run.
constexpr uint8_t kResetLineBit = 0x02;

/// Whether @p jumpers, a byte read from kJumperPort, says the recovery
/// strap is set: its bit is low. 0xFF, the floating bus of a board without
/// the jumper block, is not strapped.
constexpr bool recoveryStrapAsserted(uint8_t jumpers)
{
    return (jumpers & kRecoveryStrapBit) == 0;
}

/// Reads the jumper port now: true when the recovery strap is set.
inline bool recoveryStrapSet()
{
    return recoveryStrapAsserted(arch_x86::portRead8(kJumperPort));
}

} // namespace bsp
