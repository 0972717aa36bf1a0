// An application that publishes a ramp, for the monitoring stream's
// emulator test (tests_renode/test_mon_can.py): dcos-mon follows it over
// CAN and must see it rise by one every period.
//
// The "ramp" task writes the "ramp" publisher every 50 ms on an absolute
// schedule: bytes 0-3 the count of periods (u32, little-endian), bytes 4-5
// its negative (i16), so the test sees a signed field sign-extended, and
// byte 6 the count modulo 256 (u8). Once a second it prints
// "ramp: N" on the console, which a stream with the console flag carries
// to the host as well.
#include <bsp/Board.hpp>
#include <dcos/Application.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <runtime/Format.hpp>

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

constexpr uint64_t kPeriodNs = 50'000'000;
constexpr uint32_t kPeriodEvent = 1u << 0;
// Periods between two console lines: one a second.
constexpr uint32_t kPrintEvery = 20;

ObjectId rampPublisher;

dcos::DsmPage pageOf(uint32_t count)
{
    dcos::DsmPage page{};
    for (unsigned i = 0; i < 4; ++i) {
        page.bytes[i] = static_cast<uint8_t>(count >> (8 * i));
    }
    const uint16_t negative = static_cast<uint16_t>(-static_cast<int32_t>(count));
    page.bytes[4] = static_cast<uint8_t>(negative);
    page.bytes[5] = static_cast<uint8_t>(negative >> 8);
    page.bytes[6] = static_cast<uint8_t>(count);
    return page;
}

void rampEntry(uintptr_t)
{
    const Result<ObjectId> timer = dcos::timerAgent.Create("ramp.period", dcos::Visibility::Local);
    const Status started = timer.ok() ? dcos::timerAgent.SetPeriodicAlarm(timer.value(), kPeriodNs,
                                                                          dcos::AlarmNotification::event(kPeriodEvent))
                                      : timer.status();
    if (started != Status::Ok) {
        runtime::format(bsp::console(), "ramp: cannot start its period: %s\r\n", dcos::statusName(started));
        return;
    }
    uint32_t count = 0;
    for (;;) {
        const Result<uint32_t> events =
            dcos::taskAgent.ReceiveEvent(kPeriodEvent, dcos::EventWait::Any, dcos::kWaitForever);
        if (!events.ok()) {
            continue;
        }
        ++count;
        // A refused write (none is expected: the task owns the publisher)
        // shows as a ramp that stops, which the test sees.
        (void)dcos::dsmAgent.Write(rampPublisher, pageOf(count));
        if (count % kPrintEvery == 0) {
            runtime::format(bsp::console(), "ramp: %u\r\n", unsigned(count));
        }
    }
}

constexpr dcos::app::TaskDeclaration kTasks[] = {
    {.name = "ramp", .entry = rampEntry, .priority = 10},
};

constexpr dcos::app::PublisherDeclaration kPublishers[] = {
    {.name = "ramp", .writer = "ramp", .id = &rampPublisher},
};

} // namespace

DCOS_APPLICATION(rampApplication, {
                                      .name = "ramp",
                                      .tasks = kTasks,
                                      .publishers = kPublishers,
                                  });
