// A closed loop through the I/O board and the plant simulator (issue 5):
// a proportional controller runs as a DCOS task every 10 ms, reads the
// plant's output on AI0 and drives its input on AO0. The plant is the host
// simulator's first-order-plus-dead-time process (gain 1, time constant
// 200 ms, dead time 20 ms), joined to the board model in lock-step with
// emulated time, so the run is exact and repeatable.
//
// The controller adds a feed-forward of set point / plant gain to the
// proportional term, so that a proportional controller holds the set point
// without the offset a pure P controller would leave. The test holds the
// plant at 2 V and requires every sample of the last second to lie within
// +-20 mV of it.
#include "KernelTestSupport.hpp"

#include <iobus/AnalogScaling.hpp>
#include <iobus/MfioBoard.hpp>
#include <iobus/MfioClient.hpp>

#include <dcos/SystemAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Status;

constexpr int32_t kSetPointMicrovolts = 2000000;
constexpr int32_t kBandMicrovolts = 20000;
// Kp as a fraction: 3/2.
constexpr int32_t kGainNumerator = 3;
constexpr int32_t kGainDenominator = 2;
constexpr unsigned kPeriods = 300;      // 3 s at 10 ms.
constexpr unsigned kSettledFrom = 200;  // The last second.
constexpr uint32_t kTickEvent = 1u << 3;

iobus::MfioBoard loopBoard("mfio-loop", 0x300, 5);
ObjectId boardId;
int32_t samples[kPeriods];
volatile bool loopOk = false;

// DAC code for a voltage (offset binary over +-10 V), clamped to 12 bits.
uint16_t dacCode(int32_t microvolts)
{
    int64_t code = 2048 + (int64_t{microvolts} * 4096) / 20000000;
    code = code < 0 ? 0 : (code > 4095 ? 4095 : code);
    return static_cast<uint16_t>(code);
}

void controllerEntry(uintptr_t)
{
    const dcos::Result<ObjectId> timer = dcos::timerAgent.Create("loop-period", dcos::Visibility::Local);
    bool ok = timer.ok() &&
              dcos::timerAgent.SetPeriodicAlarm(timer.value(), 10000000, dcos::AlarmNotification::event(kTickEvent)) ==
                  Status::Ok;
    for (unsigned period = 0; period < kPeriods && ok; ++period) {
        ok = dcos::taskAgent.ReceiveEvent(kTickEvent, dcos::EventWait::Any, 100000000).ok();
        const dcos::Result<iobus::AnalogValue> y = iobus::readAnalogInputMicrovolts(boardId, 0);
        ok = ok && y.ok();
        const int32_t measured = y.ok() ? y.value().microvolts : 0;
        samples[period] = measured;
        const int32_t error = kSetPointMicrovolts - measured;
        const int32_t output = kSetPointMicrovolts + error * kGainNumerator / kGainDenominator;
        ok = ok && iobus::writeWord(boardId, iobus::channel::kAnalogOutput0, dacCode(output)) == Status::Ok;
    }
    if (timer.ok()) {
        (void)dcos::timerAgent.Delete(timer.value());
    }
    loopOk = ok;
    finished();
}

bool closedLoop(shell::Shell& shell)
{
    iobus::IsaConflict conflict;
    const dcos::Result<ObjectId> id = loopBoard.install("mfio-loop", dcos::Visibility::Local, &conflict);
    bool ok = checkStatus(shell, id.status(), Status::Ok, "install the board");
    if (!ok) {
        return false;
    }
    boardId = id.value();
    ok = checkStatus(shell, dcos::systemAgent.Open(boardId), Status::Ok, "open the board") && ok;
    (void)iobus::writeWord(boardId, iobus::channel::kAnalogOutput0, dacCode(0));
    ok = ok && check(shell, !spawn("controller", 8, controllerEntry).isNull(), "start the controller task");
    ok = ok && waitForDone(shell, 1, 10000000000ull);
    ok = check(shell, loopOk, "every period read and wrote the board") && ok;
    int32_t worst = 0;
    unsigned enteredBand = kPeriods;
    for (unsigned i = 0; i < kPeriods; ++i) {
        const int32_t deviation = samples[i] > kSetPointMicrovolts ? samples[i] - kSetPointMicrovolts
                                                                   : kSetPointMicrovolts - samples[i];
        if (i >= kSettledFrom && deviation > worst) {
            worst = deviation;
        }
        if (deviation > kBandMicrovolts) {
            enteredBand = kPeriods;
        } else if (enteredBand == kPeriods) {
            enteredBand = i;
        }
    }
    shell.print("plant output at 0.5 s %ld uV, 1 s %ld uV, 3 s %ld uV; within +-%ld uV from %u ms; worst in the last second %ld uV\r\n",
                static_cast<long>(samples[49]), static_cast<long>(samples[99]), static_cast<long>(samples[kPeriods - 1]),
                static_cast<long>(kBandMicrovolts), enteredBand * 10, static_cast<long>(worst));
    ok = check(shell, worst <= kBandMicrovolts, "the plant stays within the band in the last second") && ok;
    while (dcos::systemAgent.Close(boardId) == Status::Ok) {
    }
    (void)loopBoard.uninstall();
    return ok;
}

} // namespace

DCOS_TARGET_TEST(closedLoopTest, "closedloop", "a P controller task holds the plant simulator at 2 V within 20 mV",
                 closedLoop);

} // namespace target_test
