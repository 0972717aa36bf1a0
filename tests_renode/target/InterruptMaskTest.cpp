// Shows that a masked interrupt line delivers nothing, and that the request
// it held is delivered once the line is unmasked.
#include "TargetTest.hpp"

#include <arch_x86/Cpu.hpp>
#include <bsp/Board.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace {

// Enough busy iterations for several tick periods to elapse at any tick
// rate the board accepts; the loop ends early once the request is seen.
constexpr uint32_t spinLimit = 200000000;

bool maskedTickDoesNotArrive(shell::Shell& shell)
{
    bsp::maskInterrupt(bsp::systemTickLine);
    const uint64_t before = dcos::internal::TimerManager::ticks();

    // Wait (interrupts enabled) until the timer has raised its request.
    uint32_t spins = 0;
    while (!bsp::isInterruptRequested(bsp::systemTickLine) && spins < spinLimit) {
        ++spins;
    }
    const bool requested = bsp::isInterruptRequested(bsp::systemTickLine);
    // Let more time pass with the request pending; still nothing may arrive.
    for (uint32_t i = 0; i < 200000; ++i) {
        asm volatile("" ::: "memory"); // Keeps the delay loop from being optimised away.
    }
    const uint64_t whileMasked = dcos::internal::TimerManager::ticks();

    bsp::unmaskInterrupt(bsp::systemTickLine);
    // The pending request is delivered now; wait for it with a bound.
    uint64_t afterUnmask = dcos::internal::TimerManager::ticks();
    for (unsigned i = 0; i < 1000 && afterUnmask == whileMasked; ++i) {
        arch_x86::haltUntilInterrupt();
        afterUnmask = dcos::internal::TimerManager::ticks();
    }
    shell.print("masked: request pending %s, ticks before %llu, while masked %llu, after unmask %llu\r\n",
                requested ? "yes" : "no", static_cast<unsigned long long>(before),
                static_cast<unsigned long long>(whileMasked), static_cast<unsigned long long>(afterUnmask));
    return requested && whileMasked == before && afterUnmask > whileMasked;
}

} // namespace

DCOS_TARGET_TEST(interruptMaskTest, "irqmask", "a masked IRQ does not arrive until unmasked", maskedTickDoesNotArrive);
