// One Modbus RTU station on one serial line: the glue between a UART and
// fieldbus/modbus's portable Slave or Master.
//
// The runner owns the RTU transport and the station (a slave serving a
// DataModel, or a master), and is driven by its task with the time:
//
//   - the UART's interrupt pushes each received byte with its arrival time
//     into queue() and wakes the task; the task's service() feeds them to the
//     station in order, each with its own time, so the receive state
//     machine sees the real silences between characters;
//   - a station's step that transmits goes to the port (LinePort::transmit);
//     the port's interrupt says when the FIFO has run dry (fifoEmptied()),
//     and service() then asks the port to finish the transmission (the
//     shift register is empty: RTS released) and tells the station that its
//     frame has left the line;
//   - service() returns when it wants to run next (the t1.5/t3.5 timers, a
//     master's time-out, the check for the shift register), and the task
//     sleeps until then or until the next interrupt.
//
// It has no clock, no task and no UART of its own, so the host tests drive
// it with a fake port and simulated time; the firmware's ModbusLine gives it
// the board's RS-485 port, the timer agent's clock and a task.
#pragma once

#include <mbline/TimedByteQueue.hpp>

#include <dcos/Status.hpp>
#include <modbus/DataModel.hpp>
#include <modbus/Master.hpp>
#include <modbus/PollSchedule.hpp>
#include <modbus/RtuTransport.hpp>
#include <modbus/Server.hpp>
#include <modbus/Slave.hpp>

#include <stddef.h>
#include <stdint.h>

namespace mbline {

/// What the runner needs of a half-duplex UART.
class LinePort {
public:
    /// Starts sending one frame (turning the RS-485 driver on); Busy while
    /// the previous one is still on the line.
    virtual dcos::Status transmit(const uint8_t* bytes, size_t length) = 0;
    /// True once the frame's last stop bit has left (the driver is off).
    virtual bool finishTransmission() = 0;

protected:
    ~LinePort() = default;
};

enum class Role : uint8_t { Off, Slave, Master };

const char* roleName(Role role);

/// The line's own counters; the receiver's, the slave's and the master's
/// are theirs (transport(), slave(), master()).
struct LineCounters {
    uint32_t charactersReceived = 0;
    uint32_t framesSent = 0;
    uint32_t transmitRefused = 0;  ///< The port refused a frame (it was still sending).
    uint32_t temtPolls = 0;        ///< Checks of the shift register that found it still busy.
    uint32_t damagedCharacters = 0; ///< Characters the UART flagged (parity, framing, break).
};

/// How a master transaction ended, for the one who submitted it.
struct Completion {
    modbus::ModbusError error = modbus::ModbusError::Ok;
    modbus::ExceptionCode exception = modbus::ExceptionCode::None;
    uint8_t function = 0;
    size_t length = 0;                          ///< Bytes of the response PDU (0 for a broadcast).
    uint8_t pdu[modbus::kMaxPduLength] = {};
};

class LineRunner {
public:
    /// Received bytes waiting for the task; the interrupt pushes into it.
    static constexpr size_t kQueueCapacity = 512;
    /// The longest the transmit interrupt's handler may run after the FIFO
    /// ran dry (the tick's handler and a kernel section with interrupts off,
    /// on a 486) for the silence after a transmission to be counted right;
    /// see finishIfSent(). Under 6 % of t3.5 at any rate ([SL] 2.5.1.1: 1.75
    /// ms at least).
    static constexpr uint64_t kTransmitInterruptAllowanceNs = 100000;

    explicit LineRunner(LinePort& port) : port_(port) {}

    /// Becomes a slave at @p address serving @p model on a line with
    /// @p timing, from @p nowNs (the line must then be silent for t3.5).
    modbus::ModbusError startSlave(const modbus::RtuTiming& timing, modbus::DataModel& model,
                                   const modbus::DeviceIdentification& identification, uint8_t address,
                                   uint64_t nowNs);
    /// Becomes a master on a line with @p timing.
    modbus::ModbusError startMaster(const modbus::RtuTiming& timing, const modbus::MasterConfig& config,
                                    uint64_t nowNs);

    /// Most entries of a polling schedule (an application declares at most as many).
    static constexpr size_t kPollCapacity = 16;
    using Schedule = modbus::PollSchedule<kPollCapacity>;

    /// Becomes a master that runs a polling schedule: the schedule, empty
    /// now, is filled by the caller (schedule().add()) before the next
    /// service(); from then on the schedule submits its entries itself,
    /// and submit() is refused (Busy) while it runs them.
    modbus::ModbusError startPolling(const modbus::RtuTiming& timing, const modbus::MasterConfig& config,
                                     uint64_t nowNs);
    Schedule& schedule() { return schedule_; }
    const Schedule& schedule() const { return schedule_; }
    bool polling() const { return polling_; }
    /// The entries whose transaction ended since the last call, bit n entry n.
    uint32_t takePolled()
    {
        const uint32_t polled = polled_;
        polled_ = 0;
        return polled;
    }
    /// Leaves the line (Off). The caller has stopped the port's interrupt.
    void stop();

    /// A master's new transaction; Busy while one runs, NotExpected when not a master.
    modbus::ModbusError submit(const modbus::Request& request, uint64_t nowNs);
    /// Takes the last completed transaction; false when none is new.
    bool takeCompletion(Completion& completion);

    /// From the port's interrupt: the transmit FIFO ran dry at @p nowNs.
    void fifoEmptied(uint64_t nowNs)
    {
        fifoEmptiedAtNs_ = nowNs;
        __atomic_store_n(&fifoEmptied_, true, __ATOMIC_RELEASE);
    }

    /// Does everything due up to @p nowNs and returns when to run again
    /// (~0: only on the next interrupt).
    uint64_t service(uint64_t nowNs);

    TimedByteQueue<kQueueCapacity>& queue() { return queue_; }
    Role role() const { return role_; }
    bool transmitting() const { return transmitting_; }
    const LineCounters& counters() const { return counters_; }
    const modbus::RtuTransport& transport() const { return transport_; }
    const modbus::Slave& slave() const { return slave_; }
    const modbus::Master& master() const { return master_; }
    const modbus::RtuTiming& timing() const { return timing_; }

private:
    void feedReceived();
    void apply(const modbus::StationStep& step, uint64_t nowNs);
    void finishIfSent(uint64_t nowNs);
    /// A master's frame has left the line (or was refused): told to the schedule when polling.
    void masterTransmitDone(uint64_t nowNs);
    /// A schedule's step: the master's step, and the entry it ended.
    void applyPoll(const modbus::PollStep& step, uint64_t nowNs);

    LinePort& port_;
    Role role_ = Role::Off;
    modbus::RtuTiming timing_{};
    modbus::RtuTransport transport_{};
    modbus::Server server_{};
    modbus::Slave slave_{};
    modbus::Master master_{};
    Schedule schedule_{master_};
    bool polling_ = false;
    uint32_t polled_ = 0;
    TimedByteQueue<kQueueCapacity> queue_;
    LineCounters counters_{};
    bool transmitting_ = false;
    volatile bool fifoEmptied_ = false;
    uint64_t fifoEmptiedAtNs_ = 0; // Published by fifoEmptied_ (release, acquire).
    bool completed_ = false;
    Completion completion_{};
};

} // namespace mbline
