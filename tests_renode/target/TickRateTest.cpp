// Measures the system tick against the emulator's virtual clock.
//
// The MC146818 real-time clock is an independent time base: in the emulator
// with "-rtc clock=vm" it follows the virtual clock, and under -icount that
// clock is exact. The test waits for a seconds edge, then counts system
// ticks over the next two whole seconds.
#include "TargetTest.hpp"

#include <arch_x86/Cpu.hpp>
#include <arch_x86/PortIo.hpp>
#include <bsp/Board.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace {

// MC146818 ports and registers (datasheet, "Address Map").
constexpr uint16_t rtcIndexPort = 0x70;
constexpr uint16_t rtcDataPort = 0x71;
constexpr uint8_t rtcSeconds = 0x00;
constexpr uint8_t rtcStatusA = 0x0A;
constexpr uint8_t statusAUpdateInProgress = 1u << 7;
constexpr unsigned measuredSeconds = 2;

uint8_t readRtc(uint8_t reg)
{
    arch_x86::portWrite8(rtcIndexPort, reg);
    return arch_x86::portRead8(rtcDataPort);
}

uint8_t readSeconds()
{
    // Wait out an update cycle so the value read is consistent.
    while ((readRtc(rtcStatusA) & statusAUpdateInProgress) != 0) {
    }
    return readRtc(rtcSeconds);
}

// Sleeps tick by tick until the seconds register changes; returns the tick
// count seen right after the change.
uint64_t waitForSecondsEdge()
{
    const uint8_t start = readSeconds();
    for (;;) {
        arch_x86::haltUntilInterrupt();
        if (readSeconds() != start) {
            return dcos::internal::TimerManager::ticks();
        }
    }
}

bool measureTickRate(shell::Shell& shell)
{
    waitForSecondsEdge();
    const uint64_t first = waitForSecondsEdge();
    uint64_t last = first;
    for (unsigned i = 0; i < measuredSeconds; ++i) {
        last = waitForSecondsEdge();
    }
    const uint64_t ticks = last - first;
    // The expected count follows from the exact period the divisor gives.
    const uint64_t expected = (uint64_t{measuredSeconds} * 1000000000ull) / bsp::tickPeriodNanoseconds();
    shell.print("tick rate: %llu ticks in %u s of emulator time; configured %lu Hz, expected %llu\r\n",
                static_cast<unsigned long long>(ticks), measuredSeconds,
                static_cast<unsigned long>(bsp::tickRateHz()), static_cast<unsigned long long>(expected));
    // One tick either way: the edges are sampled at tick granularity.
    return ticks + 1 >= expected && ticks <= expected + 1;
}

} // namespace

DCOS_TARGET_TEST(tickRateTest, "tick", "count system ticks against the real-time clock", measureTickRate);
