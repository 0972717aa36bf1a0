// One of the board's RS-485 ports running a Modbus RTU line: the 16550,
// its interrupt line, the LineRunner and the task that drives it.
//
// The console's line on COM2 (ModbusCommands.cpp) and the application's
// polling line on COM3 (PollLine.cpp) are two of these: the same chip core
// and the same glue with each port's own address and line, so that the
// interrupt handling, the bring-up and the task's wait are written once.
//
//   - start() brings the UART up with the line's settings, hands received
//     bytes to the runner's queue stamped with the uptime, and attaches the
//     port's interrupt, which wakes the line's task (kLineEvent);
//   - service() is the task's round: it runs the runner up to now and says
//     how long the task may sleep; wait() sleeps that long, or until the
//     interrupt or another of the task's events.
#pragma once

#include <mbline/LineRunner.hpp>

#include <bsp/Uart16550.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace mbline {

class BoardLine final : public LinePort {
public:
    /// The task event the port's interrupt posts.
    static constexpr uint32_t kLineEvent = 1u << 0;

    BoardLine(bsp::Uart16550& uart, unsigned interruptLine, uint16_t portAddress, const char* portName)
        : uart_(uart), interruptLine_(interruptLine), portAddress_(portAddress), portName_(portName), runner_(*this)
    {
    }

    dcos::Status transmit(const uint8_t* bytes, size_t length) override { return uart_.transmit(bytes, length); }
    bool finishTransmission() override { return uart_.finishTransmission(); }

    /// Creates the line's task, @p name running @p entry, the first time
    /// it is asked for (a line lives as long as the node); the interrupt
    /// wakes it. Fails with TaskAgent::Create's status.
    dcos::Status startTask(const char* name, void (*entry)(uintptr_t));
    dcos::ObjectId task() const { return task_; }

    /// Brings the port up with @p settings (stopping it first); the runner
    /// is started by the caller. NotFound when no 16550 answers there.
    dcos::Status start(const bsp::UartSettings& settings);
    /// Detaches the interrupt, shuts the UART down and stops the runner.
    void stop();

    /// The task's round at @p nowNs: returns how long it may sleep
    /// (dcos::kWaitForever, or dcos::kPoll to run again at once).
    uint64_t service(uint64_t nowNs);
    /// Sleeps for @p timeoutNs from service(), or until kLineEvent or one of
    /// @p otherEvents; returns the events received.
    uint32_t wait(uint64_t timeoutNs, uint32_t otherEvents);

    LineRunner& runner() { return runner_; }
    const LineRunner& runner() const { return runner_; }
    const bsp::Uart16550& uart() const { return uart_; }
    unsigned interruptLine() const { return interruptLine_; }
    uint16_t portAddress() const { return portAddress_; }
    const char* portName() const { return portName_; }

private:
    static void interrupt(void* self);
    static void fifoEmptied(void* self);

    bsp::Uart16550& uart_;
    unsigned interruptLine_;
    uint16_t portAddress_;
    const char* portName_;
    LineRunner runner_;
    dcos::ObjectId task_{};
};

} // namespace mbline
