// What the dual-Pentium board adds to the board interface both boards share
// (bsp/Board.hpp).
#pragma once

#include <stdint.h>

namespace bsp {

/// The line the other node's inter-processor interrupts arrive on: the
/// PC/AT's cascade input, which no ISA device can use.
constexpr unsigned interProcessorLine = 2;

/// The processor this node runs on: 0 for node 2 (the bootstrap
/// processor), 1 for node 3. The shared-memory network's physical address.
unsigned processorIndex();

/// Whether the board's other node runs: on node 2, whether it started
/// node 3; on node 3, always.
bool otherNodeRunning();

/// The other node's node id: 3 on node 2, node 2's id on node 3.
uint16_t otherNodeId();

/// Raises line 2 on the other node's processor; false when it does not run
/// or the local APIC did not deliver the interrupt. Call with interrupts
/// disabled: the command register is one for the whole processor.
bool signalOtherNode();

} // namespace bsp
