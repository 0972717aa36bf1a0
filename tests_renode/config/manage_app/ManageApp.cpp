// An application whose image holds an entry point for dcos-config to start
// more tasks of, for the management commands' emulator test
// (tests_renode/test_config_manage.py, docs/protocols/config.md, "Objects
// and tasks").
//
// The "worker" task says "worker A: started" with its argument A, then
// counts its periods of 20 ms, saying "worker A: N" every 50th, so the
// test sees a task dcos-config created run, stop and run again. The
// application also declares the semaphore "applock" and the publisher
// "level", which a saved configuration lists and a restore leaves alone.
#include <bsp/Board.hpp>
#include <dcos/Application.hpp>
#include <dcos/TaskAgent.hpp>
#include <runtime/Format.hpp>

namespace {

constexpr uint64_t kPeriodNs = 20'000'000;
constexpr unsigned kPrintEvery = 50;

dcos::ObjectId appLock;
dcos::ObjectId level;

void workerEntry(uintptr_t argument)
{
    runtime::format(bsp::console(), "worker %u: started\r\n", unsigned(argument));
    for (unsigned periods = 1;; ++periods) {
        (void)dcos::taskAgent.SleepFor(kPeriodNs);
        if (periods % kPrintEvery == 0) {
            runtime::format(bsp::console(), "worker %u: %u\r\n", unsigned(argument), periods);
        }
    }
}

constexpr dcos::app::TaskDeclaration kTasks[] = {
    {.name = "worker", .entry = workerEntry, .priority = 12, .argument = 1},
};

constexpr dcos::app::SemaphoreDeclaration kSemaphores[] = {
    {.name = "applock", .id = &appLock},
};

constexpr dcos::app::PublisherDeclaration kPublishers[] = {
    {.name = "level", .writer = "worker", .id = &level},
};

} // namespace

DCOS_APPLICATION(manageApplication, {
                                        .name = "manage",
                                        .tasks = kTasks,
                                        .semaphores = kSemaphores,
                                        .publishers = kPublishers,
                                    });
