// The board's watchdog as the card's boot uses it (docs/boot.md, "Which
// image boots"): an iBASE IB700-compatible timer (QEMU's ib700). A write to
// port 0x443 starts it, the value's low four bits picking the time (30 s
// less 2 s per step); a write to port 0x441 stops it. The stage loader arms
// it for a trial; the trial stops it when it confirms (BootControl).
#pragma once

#include <arch_x86/PortIo.hpp>

#include <stdint.h>

namespace boot::watchdog {

constexpr uint16_t kStopPort = 0x441;
constexpr uint16_t kStartPort = 0x443;
/// Step 0: 30 seconds.
constexpr uint8_t kTrialSetting = 0;
constexpr unsigned kTrialSeconds = 30;

inline void armForTrial() { arch_x86::portWrite8(kStartPort, kTrialSetting); }
inline void stop() { arch_x86::portWrite8(kStopPort, 0); }

} // namespace boot::watchdog
