// The count of system ticks since the board started its tick timer.
//
// The tick interrupt is the only writer. Readers on a 32-bit CPU cannot load
// 64 bits atomically, so they read with interrupts disabled.
#pragma once

#include <stdint.h>

namespace dcos {

class SystemTick {
public:
    /// Called from the tick interrupt.
    static void advance() { count_ = count_ + 1; }

    /// Ticks since the tick timer started.
    static uint64_t count();

private:
    static volatile uint64_t count_;
};

} // namespace dcos
