// A reading of the clock right after the tick is counted once.
//
// QEMU's 8254 makes the tick's request visible either in the reload count
// itself or one count later. bsp::nanosecondsIntoTick takes a reading of
// the reload count with no request as a tick not counted yet, and adds it;
// a tick whose handler ran within that count would be added twice by a
// reading right after it (the clock a whole tick ahead, then held there by
// the uptime's monotonic guard). The test wakes on each tick and reads at
// once, many times, and fails if any reading is half a tick or more past
// the ticked time: the way from the tick to the reading takes a few
// microseconds, so a reading that far on has counted the tick twice (or
// been held at such a reading by the uptime's monotonic guard).
#include "TargetTest.hpp"

#include <arch_x86/Cpu.hpp>
#include <bsp/Board.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace {

bool readAfterTick(shell::Shell& shell)
{
    using dcos::internal::TimerManager;
    constexpr unsigned kWakeUps = 400;
    unsigned twice = 0;
    uint64_t worst = 0;
    for (unsigned i = 0; i < kWakeUps; ++i) {
        arch_x86::haltUntilInterrupt();
        arch_x86::InterruptGuard guard;
        const uint64_t precise = TimerManager::preciseUptimeNs();
        const uint64_t ticked = TimerManager::uptimeNs();
        const uint64_t into = precise - ticked;
        worst = into > worst ? into : worst;
        if (into >= TimerManager::tickPeriodNs() / 2) {
            ++twice;
        }
    }
    shell.print("tick counted twice in %u of %u readings right after it; furthest into a tick %llu ns of %llu\r\n",
                twice, kWakeUps, static_cast<unsigned long long>(worst),
                static_cast<unsigned long long>(TimerManager::tickPeriodNs()));
    return twice == 0;
}

} // namespace

DCOS_TARGET_TEST(tickOnceTest, "tickonce", "a reading right after the tick counts it once", readAfterTick);
