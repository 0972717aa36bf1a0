// The SJA1000 driver (drivers/can) on the card's chip, from a task that owns
// the channel: bus-off and the automatic recovery a thousand times in a row.
//
// The board of the on-target tests has no lab bus, so channel 0 is a chip
// alone on its bus (docs/protocols/labbus.md), and a recovery takes its
// 128 x 11 recessive bits on that idle bus without a hub holding the clock:
// the thousand cycles take about 1.5 s of emulated time and little more of
// wall time. The lab-bus test of the same behaviour
// (test_can_driver.py, where the hub forces the bus-off) is bounded by the
// hub's lock-step instead.
//
// The bus-off is forced the way the chip allows a processor to (DS 6.4.12;
// docs/protocols/labbus.md): in reset mode, TXERR written with 255. The chip
// then reports it as any bus-off, with BS and EI, and the driver's interrupt
// routine does the rest on its own: it logs the change for the owner, posts
// the owner's state event and, under the default policy, takes the chip out
// of reset mode to recover. The test task only forces and then waits, as the
// owner, for the driver to report the recovery.
#include "KernelTestSupport.hpp"

#include <sja1000/IsaSja1000Channel.hpp>

#include <arch_x86/PortIo.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace target_test {

namespace {

using dcos::Status;
using dcos::systemAgent;
using dcos::taskAgent;
using sja1000::ErrorState;
using sja1000::Sja1000Controller;
namespace reg = sja1000::reg;

constexpr unsigned kCycles = 1000;
constexpr uint32_t kBitRate = 1'000'000;
constexpr uint32_t kStateEvent = 1u << 12;
constexpr uint32_t kReceiveEvent = 1u << 13;
constexpr uint32_t kSentEvent = 1u << 14;
constexpr uint64_t kMillisecond = 1'000'000;
// A recovery is 128 x 11 bit times, 1.408 ms at 1 Mbit/s; four times that
// bounds a hung driver, not a slow one.
constexpr uint64_t kRecoveryTimeoutNs = 4 * 128 * 11 * 1000;

sja1000::IsaSja1000Channel channel("can-target", sja1000::kIsaCardDefaultBase, sja1000::kIsaCardDefaultIrq0);

void writeRegister(uint8_t offset, uint8_t value)
{
    arch_x86::portWrite8(static_cast<uint16_t>(sja1000::kIsaCardDefaultBase + offset), value);
}

// Forces a bus-off as a processor can: reset mode, then TXERR = 255.
void forceBusOff()
{
    writeRegister(reg::kMode, reg::kModeReset);
    writeRegister(reg::kTxErrorCounter, 255);
}

// Waits, as the owner, until the driver has logged a change to @p state;
// counts every change read into @p changes.
bool waitForChangeTo(dcos::ObjectId id, ErrorState state, unsigned& changes)
{
    const uint64_t deadline = dcos::timerAgent.Uptime() + kRecoveryTimeoutNs;
    for (;;) {
        sja1000::StateChanges log;
        if (systemAgent.Control(id, Sja1000Controller::kReadStateChanges, &log, sizeof log) != Status::Ok) {
            return false;
        }
        changes += log.count + log.lost;
        for (uint32_t i = 0; i < log.count; ++i) {
            if (log.changes[i].to == state && log.changes[i].holdChanged == 0) {
                return true;
            }
        }
        const uint64_t now = dcos::timerAgent.Uptime();
        if (now >= deadline) {
            return false;
        }
        (void)taskAgent.ReceiveEvent(kStateEvent, dcos::EventWait::Any, deadline - now);
    }
}

bool busOffCycles(shell::Shell& shell)
{
    iobus::IsaConflict conflict;
    const dcos::Result<dcos::ObjectId> installed = channel.install("can-target", dcos::Visibility::Local, &conflict);
    if (!check(shell, installed.ok(), "the channel installs")) {
        return false;
    }
    const dcos::ObjectId id = installed.value();
    uint32_t rate = kBitRate;
    sja1000::Notification owner{taskAgent.IdOfSelf(), kReceiveEvent, kStateEvent, kSentEvent};
    bool ok = checkStatus(shell, systemAgent.Open(id), Status::Ok, "open");
    ok = checkStatus(shell, systemAgent.Control(id, Sja1000Controller::kSetBitRate, &rate, sizeof rate), Status::Ok,
                     "1 Mbit/s") && ok;
    ok = checkStatus(shell, systemAgent.Control(id, Sja1000Controller::kSetNotification, &owner, sizeof owner),
                     Status::Ok, "the test task owns the channel") && ok;

    unsigned changes = 0;
    unsigned completed = 0;
    const uint64_t began = dcos::timerAgent.Uptime();
    for (; ok && completed < kCycles; ++completed) {
        forceBusOff();
        if (!waitForChangeTo(id, ErrorState::Active, changes)) {
            shell.print("cycle %u: no recovery reported within %llu ns\r\n", completed,
                        static_cast<unsigned long long>(kRecoveryTimeoutNs));
            ok = false;
            break;
        }
    }
    const uint64_t took = dcos::timerAgent.Uptime() - began;
    sja1000::ChannelStatistics s{};
    sja1000::BusState state{};
    (void)systemAgent.Control(id, Sja1000Controller::kGetStatistics, &s, sizeof s);
    (void)systemAgent.Control(id, Sja1000Controller::kGetState, &state, sizeof state);
    shell.print("%u cycles in %llu ms of uptime: bus_offs=%lu restarts=%lu recoveries=%lu actives=%lu "
                "changes read=%u interrupt_loop_limits=%lu; now TXERR %u RXERR %u\r\n",
                completed, static_cast<unsigned long long>(took / kMillisecond),
                static_cast<unsigned long>(s.busOffs), static_cast<unsigned long>(s.restarts),
                static_cast<unsigned long>(s.recoveries), static_cast<unsigned long>(s.errorActives), changes,
                static_cast<unsigned long>(s.interruptLoopLimits), state.transmitErrors, state.receiveErrors);
    ok = check(shell, completed == kCycles, "every cycle recovered") && ok;
    ok = check(shell, s.busOffs == kCycles && s.restarts == kCycles && s.recoveries == kCycles &&
                          s.errorActives == kCycles,
               "each bus-off, restart and recovery counted once") && ok;
    ok = check(shell, changes == 2 * kCycles, "the owner read every change: to bus-off and back") && ok;
    ok = check(shell, s.interruptLoopLimits == 0, "the interrupt loop never hit its bound") && ok;
    ok = check(shell, state.errorState == ErrorState::Active && state.transmitErrors == 0 && state.started == 1,
               "error-active on the bus, counters 0") && ok;
    // Every recovery waited its 128 x 11 bit times: the thousand cannot have
    // taken less.
    ok = check(shell, took >= uint64_t{kCycles} * 128 * 11 * 1000, "each recovery took its 128 x 11 bits") && ok;

    // Not locked up: a frame still goes through the chip. Alone on the bus
    // nobody acknowledges, so the check uses self test, where the chip sends
    // without an acknowledge.
    uint32_t mode = static_cast<uint32_t>(sja1000::BusMode::SelfTest);
    ok = checkStatus(shell, systemAgent.Control(id, Sja1000Controller::kSetBusMode, &mode, sizeof mode), Status::Ok,
                     "self test") && ok;
    (void)taskAgent.ReceiveEvent(kSentEvent, dcos::EventWait::Any, dcos::kPoll);
    const uint8_t data[2] = {0x0A, 0x0B};
    const can::CanFrame frame = can::CanFrame::makeData(0x1ABCDE, can::IdFormat::Extended, data, 2).value();
    const dcos::Result<size_t> written = systemAgent.Write(id, 0, &frame, sizeof frame);
    ok = check(shell, written.ok() && written.value() == sizeof frame, "a frame is queued") && ok;
    ok = check(shell, taskAgent.ReceiveEvent(kSentEvent, dcos::EventWait::Any, 10 * kMillisecond).ok(),
               "and sent") && ok;
    (void)systemAgent.Control(id, Sja1000Controller::kGetStatistics, &s, sizeof s);
    ok = check(shell, s.framesSent == 1, "sent=1") && ok;

    (void)systemAgent.Close(id);
    ok = checkStatus(shell, channel.uninstall(), Status::Ok, "the channel uninstalls") && ok;
    return ok;
}

} // namespace

DCOS_TARGET_TEST(canDriverBusOffTest, "candrvbusoff",
                 "SJA1000 driver: 1000 forced bus-offs, each recovered and reported to the owner", busOffCycles);

} // namespace target_test
