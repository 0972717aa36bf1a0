// What the dual-Pentium board adds to the board interface both boards share
// (bsp/Board.hpp).
#pragma once

namespace bsp {

/// The line the other node's inter-processor interrupts arrive on: the
/// PC/AT's cascade input, which no ISA device can use.
constexpr unsigned interProcessorLine = 2;

} // namespace bsp
