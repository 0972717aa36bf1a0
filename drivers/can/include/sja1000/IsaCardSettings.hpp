// Where the lab's two-channel ISA CAN card sits, as its switches are set
// when it leaves the factory (docs/protocols/labbus.md): the kernel's
// driver installs its channels there, and the stage loader polls the first
// one in recovery.
#pragma once

#include <stdint.h>

namespace sja1000 {

constexpr uint16_t kIsaCardDefaultBase = 0x280;
constexpr uint8_t kIsaCardDefaultIrq0 = 10;
constexpr uint8_t kIsaCardDefaultIrq1 = 11;
/// The second channel's base, from the first's.
constexpr uint16_t kIsaSecondChannelOffset = 0x20;

} // namespace sja1000
