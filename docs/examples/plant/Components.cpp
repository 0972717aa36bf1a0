// The three components of the control loop (Plant.hpp), each a task.
//
// Component 1, the sampler, converts AI0 on an absolute schedule (a
// periodic alarm) and publishes it as "pv". Component 2, the controller,
// waits for each new "pv" page, computes the output and publishes it as
// "mv". Component 3, the actuator, waits for each new "mv" page and writes
// it to AO0. Only the sampler keeps time; the other two run when their
// input arrives, so the loop's delay is the sum of the components' work
// and, when they sit on different nodes, the frames between them.
//
// The controller is a proportional controller with a feed-forward of the
// set point divided by the plant's gain (1 here), which holds the set
// point without the offset a pure P controller leaves: the law the
// single-board closed loop test uses (tests_renode/target/ClosedLoopTest.cpp).
//
// The voter (the seed's Test Case 3, Plant.hpp) is the controller and the
// actuator in one task, fed by two samplers: it votes on their process
// values, computes the same law and writes its own I/O board's output.
#include "Plant.hpp"

#include <iobus/AnalogScaling.hpp>
#include <iobus/MfioBoard.hpp>
#include <iobus/MfioClient.hpp>

#include <dcos/Application.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace plant {

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

// Kp as a fraction: 3/2.
constexpr int32_t kGainNumerator = 3;
constexpr int32_t kGainDenominator = 2;
constexpr uint32_t kPeriodEvent = 1u << 0;
// The actuator is the most urgent: an output goes to the DAC as soon as it
// exists. The controller is the least: on one node it runs after the
// sampler has published, and is itself preempted by the actuator.
constexpr uint8_t kActuatorPriority = 7;
constexpr uint8_t kSamplerPriority = 8;
constexpr uint8_t kControllerPriority = 9;

iobus::MfioBoard ioBoard("plant-io", 0x300, 5);
ObjectId board;
ObjectId statisticsLock;
volatile int32_t setPointMicrovolts = 2'000'000;

SamplerStatistics sampler;
ControllerStatistics controller;
ActuatorStatistics actuator;

// What each task was given when it was started.
ObjectId pvPublisher;
ObjectId controllerInput;
ObjectId mvPublisher;
ObjectId actuatorInput;
ObjectId actuatorBackup;
ObjectId voterInputs[2];
VoterStatistics voter;

// Runs @p update on the statistics under their semaphore. An update that
// cannot take it within a period is dropped: the console shows a period late.
template <typename Update>
void record(Update update)
{
    if (dcos::semaphoreAgent.Acquire(statisticsLock, kPeriodNs) == Status::Ok) {
        update();
        (void)dcos::semaphoreAgent.Release(statisticsLock);
    }
}

template <typename Statistics>
Statistics copyOf(const Statistics& statistics)
{
    Statistics copy{};
    record([&] { copy = statistics; });
    return copy;
}

Status ensureLock()
{
    if (!statisticsLock.isNull()) {
        return Status::Ok;
    }
    dcos::SemaphoreAttributes attributes;
    attributes.name = "plant.stats";
    attributes.priorityInheritance = true;
    const Result<ObjectId> created = dcos::semaphoreAgent.Create(attributes);
    if (!created.ok()) {
        return created.status();
    }
    statisticsLock = created.value();
    return Status::Ok;
}

// DAC code for a voltage (offset binary over +-10 V), clamped to 12 bits.
uint16_t dacCode(int32_t microvolts)
{
    int64_t code = 2048 + (int64_t{microvolts} * 4096) / 20'000'000;
    code = code < 0 ? 0 : (code > 4095 ? 4095 : code);
    return static_cast<uint16_t>(code);
}

void samplerEntry(uintptr_t)
{
    const Result<ObjectId> timer = dcos::timerAgent.Create("plant.period", dcos::Visibility::Local);
    if (!timer.ok() ||
        dcos::timerAgent.SetPeriodicAlarm(timer.value(), kPeriodNs, dcos::AlarmNotification::event(kPeriodEvent)) !=
            Status::Ok) {
        record([] { ++sampler.errors; });
        return;
    }
    for (;;) {
        (void)dcos::taskAgent.ReceiveEvent(kPeriodEvent, dcos::EventWait::Any, dcos::kWaitForever);
        const uint64_t now = dcos::timerAgent.Uptime();
        const Result<iobus::AnalogValue> value = iobus::readAnalogInputMicrovolts(board, 0);
        Status status = value.status();
        if (value.ok()) {
            status = dcos::dsmAgent.Write(pvPublisher, encode(Signal{value.value().microvolts, now})).status();
        }
        record([&] {
            if (status == Status::Ok) {
                ++sampler.samples;
                sampler.lastMicrovolts = value.value().microvolts;
            } else {
                ++sampler.errors;
            }
        });
    }
}

// Waits for each new page of @p subscription and hands it to @p use;
// counts time-outs with @p timedOut. Returns when the publisher is deleted.
template <typename Use, typename TimedOut>
void follow(ObjectId subscription, Use use, TimedOut timedOut)
{
    uint32_t seen = dcos::kNoDsmData;
    for (;;) {
        dcos::DsmPage page;
        const Result<uint32_t> read = dcos::dsmAgent.Read(subscription, seen, page, kReadTimeoutNs);
        if (read.status() == Status::Timeout) {
            timedOut();
            continue;
        }
        if (!read.ok()) {
            return; // Deleted, or the subscription is gone.
        }
        seen = read.value();
        use(decode(page));
    }
}

void controllerEntry(uintptr_t)
{
    const Result<ObjectId> subscription = dcos::dsmAgent.Open(controllerInput);
    if (!subscription.ok()) {
        record([] { ++controller.errors; });
        return;
    }
    follow(
        subscription.value(),
        [](const Signal& pv) {
            const Signal mv{controlOutput(setPointMicrovolts, pv.microvolts), pv.sampledNs};
            const Status status = dcos::dsmAgent.Write(mvPublisher, encode(mv)).status();
            record([&] {
                ++controller.cycles;
                controller.lastPv = pv.microvolts;
                controller.lastMv = mv.microvolts;
                controller.errors += status == Status::Ok ? 0 : 1;
            });
        },
        [] { record([] { ++controller.timeouts; }); });
    record([] { ++controller.errors; });
}

// Writes one controller output to AO0 and counts it.
void actuate(const Signal& mv)
{
    const Status status = iobus::writeWord(board, iobus::channel::kAnalogOutput0, dacCode(mv.microvolts));
    // The sample's uptime is the sampler's node's: on another node it is
    // comparable only when the two clocks started together (as in the lab),
    // and a sample that seems to come from the future counts as no delay.
    const uint64_t now = dcos::timerAgent.Uptime();
    const uint64_t delay = now > mv.sampledNs ? now - mv.sampledNs : 0;
    record([&] {
        if (status != Status::Ok) {
            ++actuator.errors;
            return;
        }
        ++actuator.writes;
        actuator.lastMv = mv.microvolts;
        actuator.lastDelayNs = delay;
        actuator.maxDelayNs = delay > actuator.maxDelayNs ? delay : actuator.maxDelayNs;
    });
}

void actuatorEntry(uintptr_t)
{
    const Result<ObjectId> subscription = dcos::dsmAgent.Open(actuatorInput);
    if (!subscription.ok()) {
        record([] { ++actuator.errors; });
        return;
    }
    if (actuatorBackup.isNull()) {
        follow(subscription.value(), actuate, [] { record([] { ++actuator.timeouts; }); });
        record([] { ++actuator.errors; });
        return;
    }
    const Result<ObjectId> backup = dcos::dsmAgent.Open(actuatorBackup);
    if (!backup.ok()) {
        record([] { ++actuator.errors; });
        return;
    }
    // Active backup redundancy: wait on the followed controller's output,
    // and take the other's pages too (polling, so that a take-over starts
    // from its newest page, not an old one). Both compute from the same
    // sample, so either is right.
    ObjectId followed = subscription.value();
    ObjectId other = backup.value();
    uint32_t seenFollowed = dcos::kNoDsmData;
    uint32_t seenOther = dcos::kNoDsmData;
    for (;;) {
        dcos::DsmPage page;
        const Result<uint32_t> read = dcos::dsmAgent.Read(followed, seenFollowed, page, kFailoverNs);
        if (read.ok()) {
            seenFollowed = read.value();
            actuate(decode(page));
            dcos::DsmPage ignored;
            const Result<uint32_t> polled = dcos::dsmAgent.Read(other, seenOther, ignored, dcos::kPoll);
            seenOther = polled.ok() ? polled.value() : seenOther;
            continue;
        }
        // Silent (or deleted): the other controller takes over.
        const ObjectId silent = followed;
        followed = other;
        other = silent;
        const uint32_t seen = seenFollowed;
        seenFollowed = seenOther;
        seenOther = seen;
        record([] {
            ++actuator.failovers;
            ++actuator.timeouts;
        });
    }
}

// One of the voter's two samplers: its subscription, the last page's data
// identifier and value, and how many cycles ago that page came.
struct Source {
    ObjectId subscription;
    uint32_t seen = dcos::kNoDsmData;
    int32_t microvolts = 0;
    uint32_t age = kFreshCycles + 1;
    bool gone = false; ///< Its publisher was deleted.
};

// Takes the other sampler's newest page, if one came, without waiting.
void poll(Source& source)
{
    dcos::DsmPage page;
    const Result<uint32_t> polled = dcos::dsmAgent.Read(source.subscription, source.seen, page, dcos::kPoll);
    if (polled.ok()) {
        source.seen = polled.value();
        source.microvolts = decode(page).microvolts;
        source.age = 0;
    } else if (source.age <= kFreshCycles) {
        ++source.age;
    }
}

void voterEntry(uintptr_t)
{
    Source sources[2];
    for (unsigned i = 0; i < 2; ++i) {
        const Result<ObjectId> opened = dcos::dsmAgent.Open(voterInputs[i]);
        if (!opened.ok()) {
            record([] { ++voter.errors; });
            return;
        }
        sources[i].subscription = opened.value();
    }
    Source* followed = &sources[0];
    Source* other = &sources[1];
    bool haveLast = false;
    int32_t lastPv = 0;
    for (;;) {
        dcos::DsmPage page;
        const Result<uint32_t> read = dcos::dsmAgent.Read(followed->subscription, followed->seen, page, kFailoverNs);
        if (!read.ok()) {
            // Silent (its node or its bus died) or deleted: follow the other.
            followed->gone = read.status() != Status::Timeout;
            followed->age = kFreshCycles + 1;
            Source* const silent = followed;
            followed = other;
            other = silent;
            record([] { ++voter.failovers; });
            if (followed->gone && other->gone) {
                record([] { ++voter.errors; });
                return; // Both publishers deleted: nothing left to vote on.
            }
            continue;
        }
        followed->seen = read.value();
        followed->microvolts = decode(page).microvolts;
        poll(*other);
        const Vote chosen = vote(followed->microvolts, other->age <= kFreshCycles, other->microvolts, haveLast, lastPv);
        haveLast = true;
        lastPv = chosen.microvolts;
        const int32_t mv = controlOutput(setPointMicrovolts, chosen.microvolts);
        Status status = iobus::writeWord(board, iobus::channel::kAnalogOutput0 + kVoterOutput, dacCode(mv));
        // The read-back checks that the output took: a broken output stage or
        // wire shows as a read-back error, not only as a plant that drifts.
        const Result<iobus::AnalogValue> readBack =
            status == Status::Ok ? iobus::readAnalogInputMicrovolts(board, kVoterReadBack) : Result<iobus::AnalogValue>(status);
        status = readBack.status();
        const int32_t deviation = readBack.ok() ? readBack.value().microvolts - mv : 0;
        record([&] {
            ++voter.cycles;
            voter.lastPv = chosen.microvolts;
            voter.lastMv = mv;
            voter.agreed += chosen.kind == VoteKind::Agreed ? 1 : 0;
            voter.disagreed += chosen.kind == VoteKind::Disagreed ? 1 : 0;
            voter.single += chosen.kind == VoteKind::Single ? 1 : 0;
            voter.errors += status == Status::Ok ? 0 : 1;
            voter.readBackErrors +=
                (deviation > kReadBackToleranceMicrovolts || deviation < -kReadBackToleranceMicrovolts) ? 1 : 0;
        });
    }
}

Result<ObjectId> createTask(const char* name, uint8_t priority, dcos::TaskEntry entry)
{
    dcos::TaskAttributes attributes;
    attributes.name = name;
    attributes.priority = priority;
    return dcos::taskAgent.Create(attributes, entry, 0);
}

// Gives @p publisher to @p task, its only writer from then on.
Result<ObjectId> handOver(ObjectId publisher, const Result<ObjectId>& task)
{
    if (!task.ok()) {
        return task.status();
    }
    const Status handed = dcos::dsmAgent.XferOwnership(publisher, task.value());
    if (handed != Status::Ok) {
        return handed;
    }
    return publisher;
}

} // namespace

dcos::DsmPage encode(const Signal& signal)
{
    dcos::DsmPage page{};
    const auto raw = static_cast<uint32_t>(signal.microvolts);
    for (unsigned i = 0; i < 4; ++i) {
        page.bytes[i] = static_cast<uint8_t>(raw >> (8 * i));
    }
    for (unsigned i = 0; i < 8; ++i) {
        page.bytes[4 + i] = static_cast<uint8_t>(signal.sampledNs >> (8 * i));
    }
    return page;
}

Signal decode(const dcos::DsmPage& page)
{
    uint32_t raw = 0;
    for (unsigned i = 0; i < 4; ++i) {
        raw |= static_cast<uint32_t>(page.bytes[i]) << (8 * i);
    }
    uint64_t sampled = 0;
    for (unsigned i = 0; i < 8; ++i) {
        sampled |= static_cast<uint64_t>(page.bytes[4 + i]) << (8 * i);
    }
    return Signal{static_cast<int32_t>(raw), sampled};
}

Status installBoard()
{
    if (!board.isNull()) {
        return Status::Ok;
    }
    iobus::IsaConflict conflict;
    const Result<ObjectId> installed = ioBoard.install("plant-io", dcos::Visibility::Local, &conflict);
    if (!installed.ok()) {
        return installed.status();
    }
    const Status opened = dcos::systemAgent.Open(installed.value());
    if (opened != Status::Ok) {
        (void)ioBoard.uninstall();
        return opened;
    }
    board = installed.value();
    return iobus::writeWord(board, iobus::channel::kAnalogOutput0, dacCode(0));
}

Result<ObjectId> startSampler()
{
    if (!pvPublisher.isNull()) {
        return Status::AlreadyExists;
    }
    Status status = ensureLock();
    status = status == Status::Ok ? installBoard() : status;
    if (status != Status::Ok) {
        return status;
    }
    // The publisher belongs to the console task that creates it; the
    // sampler writes it once it is handed over (single writer).
    const Result<ObjectId> pv = dcos::dsmAgent.Create("pv", dcos::Visibility::Global);
    if (!pv.ok()) {
        return pv.status();
    }
    pvPublisher = pv.value();
    return handOver(pvPublisher, createTask("sampler", kSamplerPriority, samplerEntry));
}

Result<ObjectId> startController(ObjectId pv)
{
    if (!mvPublisher.isNull()) {
        return Status::AlreadyExists;
    }
    const Status locked = ensureLock();
    if (locked != Status::Ok) {
        return locked;
    }
    const Result<ObjectId> mv = dcos::dsmAgent.Create("mv", dcos::Visibility::Global);
    if (!mv.ok()) {
        return mv.status();
    }
    mvPublisher = mv.value();
    controllerInput = pv;
    return handOver(mvPublisher, createTask("controller", kControllerPriority, controllerEntry));
}

Status startActuator(ObjectId mv, ObjectId backup)
{
    if (!actuatorInput.isNull()) {
        return Status::AlreadyExists;
    }
    Status status = ensureLock();
    status = status == Status::Ok ? installBoard() : status;
    if (status != Status::Ok) {
        return status;
    }
    actuatorInput = mv;
    actuatorBackup = backup;
    return createTask("actuator", kActuatorPriority, actuatorEntry).status();
}

Status startVoter(ObjectId pv, ObjectId otherPv)
{
    if (!voterInputs[0].isNull()) {
        return Status::AlreadyExists;
    }
    if (pv.isNull() || otherPv.isNull() || pv == otherPv) {
        return Status::InvalidArgument;
    }
    Status status = ensureLock();
    status = status == Status::Ok ? installBoard() : status;
    if (status != Status::Ok) {
        return status;
    }
    voterInputs[0] = pv;
    voterInputs[1] = otherPv;
    return createTask("voter", kActuatorPriority, voterEntry).status();
}

int32_t controlOutput(int32_t setPointMicrovolts, int32_t pvMicrovolts)
{
    const int32_t error = setPointMicrovolts - pvMicrovolts;
    return setPointMicrovolts + error * kGainNumerator / kGainDenominator;
}

Vote vote(int32_t followed, bool otherFresh, int32_t other, bool haveLast, int32_t last)
{
    if (!otherFresh) {
        return Vote{followed, VoteKind::Single};
    }
    const int64_t difference = int64_t{followed} - other;
    if (difference <= kAgreeMicrovolts && difference >= -kAgreeMicrovolts) {
        return Vote{static_cast<int32_t>((int64_t{followed} + other) / 2), VoteKind::Agreed};
    }
    if (!haveLast) {
        return Vote{followed, VoteKind::Disagreed};
    }
    const int64_t fromFollowed = int64_t{followed} - last;
    const int64_t fromOther = int64_t{other} - last;
    const bool otherNearer = (fromOther < 0 ? -fromOther : fromOther) < (fromFollowed < 0 ? -fromFollowed : fromFollowed);
    return Vote{otherNearer ? other : followed, VoteKind::Disagreed};
}

void setSetPoint(int32_t microvolts) { setPointMicrovolts = microvolts; }
int32_t setPoint() { return setPointMicrovolts; }

SamplerStatistics samplerStatistics() { return copyOf(sampler); }
ControllerStatistics controllerStatistics() { return copyOf(controller); }
ActuatorStatistics actuatorStatistics() { return copyOf(actuator); }
VoterStatistics voterStatistics() { return copyOf(voter); }

// The application declares no objects: the console command starts the
// components a node is to run, so one image serves every configuration.
DCOS_APPLICATION(plantApplication, {.name = "plant"});

} // namespace plant
