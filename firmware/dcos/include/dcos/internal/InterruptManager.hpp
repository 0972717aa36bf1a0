// The system agent's interrupt management (seed 7.3.3): InstallISR and
// SetInterruptLevel with its legal limit per task priority.
//
// Interrupt levels follow the interrupt controller's priorities: level 0 is
// the system tick and cannot be masked; a larger number is a lower priority.
// A task at level L holds off every line of level L or above while it runs;
// the kernel restores each task's level across task switches.
#pragma once

#include <dcos/Status.hpp>

#include <stdint.h>

namespace dcos::internal {

class InterruptManager {
public:
    /// The level of a task that masks nothing.
    static constexpr uint8_t kNoLevel = 0xFF;

    /// Attaches handler(context) to a hardware interrupt line. Handlers run
    /// with interrupts enabled, so more urgent lines nest; a task they ready
    /// is dispatched when the outermost handler returns. Privileged.
    static Status installIsr(unsigned line, void (*handler)(void* context), void* context);
    /// Detaches the handler of a line installed with installIsr. Privileged.
    static Status removeIsr(unsigned line);

    /// Sets the calling task's interrupt level, clamped to the legal limit of
    /// its priority; returns the level in force.
    static Result<uint8_t> setInterruptLevel(uint8_t level);
    /// Sets the most urgent level a task of the given priority may set. Privileged.
    static Status setLegalLimit(uint8_t priority, uint8_t level);
    static uint8_t legalLimit(uint8_t priority);

    /// Applies a task's level to the interrupt controller (task switch).
    static void applyTaskLevel(uint8_t level);
};

} // namespace dcos::internal
