// One of the board's RS-485 ports running a Modbus RTU line.
#include <mbline/BoardLine.hpp>
#include <mbline/LineInterrupt.hpp>
#include <mbline/LineService.hpp>

#include <bsp/Board.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace mbline {

using dcos::Status;
using dcos::taskAgent;
using dcos::timerAgent;

void BoardLine::interrupt(void* self)
{
    BoardLine& line = *static_cast<BoardLine*>(self);
    line.uart_.handleInterrupt();
    (void)taskAgent.PostEvent(line.task_, kLineEvent);
}

void BoardLine::fifoEmptied(void* self) { static_cast<BoardLine*>(self)->runner_.fifoEmptied(timerAgent.Uptime()); }

void stampReceivedByte(void* runner, uint8_t byte, bool damaged)
{
    // A full queue counts the byte as lost (TimedByteQueue::push); the
    // frame it belonged to then fails its CRC and is discarded.
    (void)static_cast<LineRunner*>(runner)->queue().push(byte, timerAgent.Uptime(), damaged);
}

bsp::UartSettings lineSettings(uint32_t baud, dcos::app::ModbusParity parity)
{
    return bsp::UartSettings{.baud = baud,
                             .dataBits = 8,
                             .parity = parity == dcos::app::ModbusParity::None  ? bsp::UartParity::None
                                       : parity == dcos::app::ModbusParity::Odd ? bsp::UartParity::Odd
                                                                                : bsp::UartParity::Even,
                             .stopBits = static_cast<uint8_t>(parity == dcos::app::ModbusParity::None ? 2 : 1),
                             .receiveTrigger = 1,
                             .driverEnable = bsp::DriverEnable::Rts};
}

Status BoardLine::startTask(const char* name, void (*entry)(uintptr_t))
{
    if (!task_.isNull()) {
        return Status::Ok;
    }
    // Above the application's tasks by default (16) and below the console,
    // so that a line keeps its character timing while the application works.
    constexpr uint8_t kLineTaskPriority = 6;
    dcos::TaskAttributes attributes;
    attributes.name = name;
    attributes.priority = kLineTaskPriority;
    attributes.stackSize = 8192;
    attributes.newProcess = true;
    const dcos::Result<dcos::ObjectId> task = taskAgent.Create(attributes, entry, 0);
    if (!task.ok()) {
        return task.status();
    }
    task_ = task.value();
    return Status::Ok;
}

void BoardLine::stop()
{
    (void)bsp::detachInterrupt(interruptLine_);
    uart_.shutdown();
    runner_.stop();
}

Status BoardLine::start(const bsp::UartSettings& settings)
{
    stop();
    const Status status = uart_.initialise(settings);
    if (status != Status::Ok) {
        return status;
    }
    uart_.setReceiveSink(stampReceivedByte, &runner_);
    uart_.setTransmitNotifier(fifoEmptied, this);
    return bsp::attachInterrupt(interruptLine_, interrupt, this);
}

uint64_t BoardLine::service(uint64_t nowNs)
{
    const uint64_t next = runner_.service(nowNs);
    if (next == ~0ull) {
        return dcos::kWaitForever;
    }
    const uint64_t later = timerAgent.Uptime();
    // A deadline already passed is served by the next round at once.
    return next > later ? next - later : dcos::kPoll;
}

uint32_t BoardLine::wait(uint64_t timeoutNs, uint32_t otherEvents)
{
    if (timeoutNs == dcos::kPoll) {
        return 0;
    }
    const dcos::Result<uint32_t> events =
        taskAgent.ReceiveEvent(kLineEvent | otherEvents, dcos::EventWait::Any, timeoutNs);
    return events.ok() ? events.value() : 0;
}

} // namespace mbline
