// Restarting the board from software, as a power cycle would: the
// processor's reset line, pulsed by the keyboard controller. The kernel's
// flash service restarts the node so into a new image, and the stage
// loader after a flash in recovery.
#pragma once

namespace bsp {

/// Pulses the processor's reset line (8042 command 0xFE, IBM PC/AT
/// Technical Reference, "Keyboard controller commands"). Waits a bounded
/// time for the controller's input buffer first; halts if the board does
/// not reset.
[[noreturn]] void resetBoard();

} // namespace bsp
