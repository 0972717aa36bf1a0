#include <mbline/LineRunner.hpp>

namespace mbline {

using modbus::ModbusError;

const char* roleName(Role role)
{
    switch (role) {
    case Role::Off: return "off";
    case Role::Slave: return "slave";
    case Role::Master: return "master";
    }
    return "?";
}

ModbusError LineRunner::startSlave(const modbus::RtuTiming& timing, modbus::DataModel& model,
                                   const modbus::DeviceIdentification& identification, uint8_t address,
                                   uint64_t nowNs)
{
    stop();
    modbus::ModbusResult<modbus::Server> server = modbus::Server::create(model, identification);
    if (!server.ok()) {
        return server.error();
    }
    server_ = server.value();
    timing_ = timing;
    transport_ = modbus::RtuTransport(timing);
    transport_.onTransmitDone(nowNs); // The line must be silent for t3.5 before the first frame.
    modbus::ModbusResult<modbus::Slave> slave = modbus::Slave::create(transport_, server_, address);
    if (!slave.ok()) {
        return slave.error();
    }
    slave_ = slave.value();
    role_ = Role::Slave;
    return ModbusError::Ok;
}

ModbusError LineRunner::startMaster(const modbus::RtuTiming& timing, const modbus::MasterConfig& config,
                                    uint64_t nowNs)
{
    stop();
    timing_ = timing;
    transport_ = modbus::RtuTransport(timing);
    transport_.onTransmitDone(nowNs);
    modbus::ModbusResult<modbus::Master> master = modbus::Master::create(transport_, config);
    if (!master.ok()) {
        return master.error();
    }
    master_ = master.value();
    role_ = Role::Master;
    return ModbusError::Ok;
}

ModbusError LineRunner::startPolling(const modbus::RtuTiming& timing, const modbus::MasterConfig& config,
                                     uint64_t nowNs)
{
    const ModbusError error = startMaster(timing, config, nowNs);
    if (error == ModbusError::Ok) {
        schedule_.clear();
        polling_ = true;
    }
    return error;
}

void LineRunner::stop()
{
    role_ = Role::Off;
    polling_ = false;
    polled_ = 0;
    transmitting_ = false;
    fifoEmptied_ = false;
    completed_ = false;
    queue_.clear();
}

ModbusError LineRunner::submit(const modbus::Request& request, uint64_t nowNs)
{
    if (role_ != Role::Master) {
        return ModbusError::NotExpected;
    }
    if (polling_) {
        return ModbusError::Busy; // The schedule has the master.
    }
    completed_ = false;
    const modbus::StationStep step = master_.submit(request, nowNs);
    if (step.rejected != ModbusError::Ok) {
        return step.rejected;
    }
    apply(step, nowNs);
    return ModbusError::Ok;
}

bool LineRunner::takeCompletion(Completion& completion)
{
    if (!completed_) {
        return false;
    }
    completion = completion_;
    completed_ = false;
    return true;
}

void LineRunner::apply(const modbus::StationStep& step, uint64_t nowNs)
{
    if (step.transmit != nullptr && step.transmitLength != 0) {
        if (port_.transmit(step.transmit, step.transmitLength) == dcos::Status::Ok) {
            transmitting_ = true;
            ++counters_.framesSent;
        } else {
            // The station waits for a transmit-done that will not come for
            // this frame; tell it the frame is gone so that it goes on (a
            // master times out and retries, a slave serves the next request).
            ++counters_.transmitRefused;
            if (role_ == Role::Slave) {
                (void)slave_.onTransmitDone(nowNs);
            } else if (role_ == Role::Master) {
                masterTransmitDone(nowNs);
            }
        }
    }
    if (step.completed && role_ == Role::Master) {
        completion_.error = step.error;
        completion_.exception = step.exception;
        const modbus::ResponseView response = master_.response();
        completion_.function = response.function();
        completion_.length = step.error == ModbusError::Ok || step.error == ModbusError::ExceptionResponse
                                 ? response.length()
                                 : 0;
        for (size_t i = 0; i < completion_.length; ++i) {
            completion_.pdu[i] = response.pdu()[i];
        }
        completed_ = true;
    }
}

void LineRunner::applyPoll(const modbus::PollStep& step, uint64_t nowNs)
{
    apply(step, nowNs);
    if (step.completed) {
        polled_ |= 1u << step.entry;
    }
}

void LineRunner::masterTransmitDone(uint64_t nowNs)
{
    if (polling_) {
        applyPoll(schedule_.onTransmitDone(nowNs), nowNs);
    } else {
        apply(master_.onTransmitDone(nowNs), nowNs);
    }
}

void LineRunner::finishIfSent(uint64_t nowNs)
{
    if (!transmitting_ || !__atomic_load_n(&fifoEmptied_, __ATOMIC_ACQUIRE)) {
        return;
    }
    if (!port_.finishTransmission()) {
        ++counters_.temtPolls;
        return;
    }
    // The last stop bit left one character time after the FIFO ran dry;
    // that, not the moment this task noticed, is when the line fell silent.
    // The interrupt stamped the FIFO's end when its handler ran, up to
    // kTransmitInterruptAllowanceNs later, and a silence counted from that
    // stamp would come out short by as much: an answer begun exactly t3.5
    // after the request ([SL] 2.5.1.1 allows it) would be taken for one begun
    // within the silence and ignored. The line is counted silent from the
    // earliest the stop bit can have left; taking an answer that began a few
    // microseconds early costs nothing, as nobody else talks after a request.
    const uint64_t stampedDoneNs = fifoEmptiedAtNs_ + timing_.characterNs;
    uint64_t doneNs = stampedDoneNs > kTransmitInterruptAllowanceNs ? stampedDoneNs - kTransmitInterruptAllowanceNs : 0;
    doneNs = doneNs < nowNs ? doneNs : nowNs;
    transmitting_ = false;
    fifoEmptied_ = false;
    if (role_ == Role::Slave) {
        (void)slave_.onTransmitDone(doneNs);
    } else if (role_ == Role::Master) {
        masterTransmitDone(doneNs);
    }
}

void LineRunner::feedReceived()
{
    // Bytes are fed one by one with their own times; a run of bytes with
    // one time (a FIFO burst) would do as well, but one at a time keeps
    // the receiver's silence arithmetic exact for every byte.
    TimedByte received;
    for (size_t i = 0; i < kQueueCapacity && queue_.pop(received); ++i) {
        ++counters_.charactersReceived;
        if (role_ == Role::Slave) {
            apply(slave_.onBytes(&received.byte, 1, received.timeNs), received.timeNs);
        } else if (polling_) {
            applyPoll(schedule_.onBytes(&received.byte, 1, received.timeNs), received.timeNs);
        } else if (role_ == Role::Master) {
            apply(master_.onBytes(&received.byte, 1, received.timeNs), received.timeNs);
        }
        if (received.damaged) {
            // A frame with a damaged character is not OK whatever its CRC
            // says (a CRC misses one error pattern in 65,536).
            ++counters_.damagedCharacters;
            transport_.markLastCharacterDamaged();
        }
    }
}

uint64_t LineRunner::service(uint64_t nowNs)
{
    if (role_ == Role::Off) {
        queue_.clear();
        return ~0ull;
    }
    finishIfSent(nowNs);
    feedReceived();
    // A byte is stamped when its stop bit has arrived, so at nowNs a
    // character may still be coming in that began up to one character time
    // ago; the line is known to have been silent only up to then. Polling
    // at nowNs itself would take that character's own time for silence and
    // could end a frame at a false t1.5 whenever the task wakes for another
    // reason (a console command, the transmit interrupt) in mid-character.
    const uint64_t silentUntilNs = nowNs > timing_.characterNs ? nowNs - timing_.characterNs : 0;
    if (role_ == Role::Slave) {
        apply(slave_.poll(silentUntilNs), nowNs);
    } else if (polling_) {
        applyPoll(schedule_.poll(silentUntilNs), nowNs);
    } else {
        apply(master_.poll(silentUntilNs), nowNs);
    }
    // A transmit interrupt that comes after the check above posts the
    // task's event, so the shift register is looked at again on that wake.
    uint64_t next = role_ == Role::Slave ? slave_.nextDeadlineNs()
                    : polling_          ? schedule_.nextDeadlineNs()
                                        : master_.nextDeadlineNs();
    if (next != ~0ull) {
        // The station's deadline is in line time; it is reached when the
        // line is known silent up to it, one character time later.
        next += timing_.characterNs;
    }
    if (transmitting_ && __atomic_load_n(&fifoEmptied_, __ATOMIC_ACQUIRE)) {
        // The shift register still holds the last byte: look again after it.
        const uint64_t again = nowNs + timing_.characterNs;
        next = again < next ? again : next;
    }
    return next;
}

} // namespace mbline
