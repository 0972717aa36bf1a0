// A polling schedule: a fixed table of requests a master runs in a cycle,
// each at its own period, keeping the last response and statistics of each.
//
// This is how a controller reads its field devices: "every 100 ms the
// temperatures of slave 3, every second the status of slave 7". The table is
// filled once at start-up (add()), then the schedule stands in for the master:
// the caller feeds it received bytes, "transmit done" and the time exactly as
// it would a Master. When the master is idle, the entry due earliest (the
// lower index on a tie) is submitted; the next due time is the previous one
// plus the period, so the cycle does not drift with the transaction times. An
// entry that fell a whole period or more behind (a slow line, a dead slave
// eating its retries) is rescheduled from now and the skipped cycles are
// counted as overruns instead of being run in a burst.
//
// Storage is static: Capacity entries, each with its request and room for a
// whole response, checked by static_assert.
#pragma once

#include <modbus/Master.hpp>

namespace modbus {

/// What happened to one entry of a schedule.
struct PollStatistics {
    uint32_t transactions = 0;  ///< Transactions run.
    uint32_t successes = 0;     ///< Ended with a normal response (or a broadcast sent).
    uint32_t exceptions = 0;    ///< Ended with an exception response.
    uint32_t timeouts = 0;      ///< Ended with no response after every retry.
    uint32_t errors = 0;        ///< Ended with a malformed response after every retry.
    uint32_t overruns = 0;      ///< Cycles skipped because the entry fell a period behind.
    ModbusError lastError = ModbusError::Ok;             ///< How the last transaction ended.
    ExceptionCode lastException = ExceptionCode::None;   ///< Its exception code, if any.
    uint64_t lastCompletedNs = 0;  ///< When the last transaction ended.
    uint64_t lastSuccessNs = 0;    ///< When the last normal response arrived.
};

/// A step of a schedule: the master's step, and which entry a completion is for.
struct PollStep : StationStep {
    size_t entry = 0;
};

template <size_t Capacity>
class PollSchedule {
public:
    static_assert(Capacity >= 1 && Capacity <= 255, "a schedule has 1 to 255 entries");

    /// A schedule driving @p master (which outlives it).
    explicit PollSchedule(Master& master) : master_(&master) {}

    /// Appends @p request, run every @p periodNs from @p firstDueNs; returns
    /// the entry's index, or InvalidArgument for a period of 0, BufferTooSmall
    /// when the table is full.
    ModbusResult<size_t> add(const Request& request, uint64_t periodNs, uint64_t firstDueNs = 0)
    {
        if (periodNs == 0 || request.length == 0) {
            return ModbusError::InvalidArgument;
        }
        if (count_ == Capacity) {
            return ModbusError::BufferTooSmall;
        }
        Entry& entry = entries_[count_];
        entry.request = request;
        entry.periodNs = periodNs;
        entry.dueNs = firstDueNs;
        return count_++;
    }

    /// Empties the table, so that add() fills it again; the master stays. In
    /// place: a schedule is too large to be built anew on a task's stack.
    void clear()
    {
        for (size_t i = 0; i < count_; ++i) {
            entries_[i] = Entry{};
        }
        count_ = 0;
        current_ = 0;
    }

    /// Replaces the request of @p entry, keeping its period, due time and
    /// statistics: an entry that writes values the application changes
    /// sends them from its next submission on (a transaction under way
    /// keeps its ADU, retries included). InvalidArgument for an empty
    /// request or an entry that does not exist.
    ModbusError replace(size_t entry, const Request& request)
    {
        if (entry >= count_ || request.length == 0) {
            return ModbusError::InvalidArgument;
        }
        entries_[entry].request = request;
        return ModbusError::Ok;
    }

    /// Bytes received from the line at @p nowNs.
    PollStep onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs)
    {
        return record(master_->onBytes(bytes, count, nowNs), nowNs);
    }

    /// Lets time pass, and submits the entry that is due when the master is idle.
    PollStep poll(uint64_t nowNs)
    {
        PollStep step = record(master_->poll(nowNs), nowNs);
        if (!master_->idle() || count_ == 0) {
            return step;
        }
        size_t due = count_;
        for (size_t i = 0; i < count_; ++i) {
            if (entries_[i].dueNs <= nowNs && (due == count_ || entries_[i].dueNs < entries_[due].dueNs)) {
                due = i;
            }
        }
        if (due == count_) {
            return step;
        }
        Entry& entry = entries_[due];
        entry.dueNs += entry.periodNs;
        if (entry.dueNs <= nowNs) {
            const uint64_t behind = nowNs - entry.dueNs;
            entry.statistics.overruns += static_cast<uint32_t>(behind / entry.periodNs + 1);
            entry.dueNs = nowNs + entry.periodNs;
        }
        const StationStep submitted = master_->submit(entry.request, nowNs);
        if (submitted.rejected != ModbusError::Ok) {
            // The request was accepted by add() but the transport cannot
            // frame it: it ends as a failed transaction of its entry.
            entry.statistics.transactions++;
            entry.statistics.errors++;
            entry.statistics.lastError = submitted.rejected;
            entry.statistics.lastCompletedNs = nowNs;
            return step;
        }
        current_ = due;
        entry.statistics.transactions++;
        step.transmit = submitted.transmit;
        step.transmitLength = submitted.transmitLength;
        return step;
    }

    /// The request handed over by the last step has left the line at @p nowNs.
    PollStep onTransmitDone(uint64_t nowNs) { return record(master_->onTransmitDone(nowNs), nowNs); }

    /// When poll() has something to do: the master's deadline, or the next
    /// entry's due time when the master is idle.
    uint64_t nextDeadlineNs() const
    {
        uint64_t next = master_->nextDeadlineNs();
        if (master_->idle()) {
            for (size_t i = 0; i < count_; ++i) {
                if (entries_[i].dueNs < next) {
                    next = entries_[i].dueNs;
                }
            }
        }
        return next;
    }

    size_t size() const { return count_; }
    const Request& request(size_t entry) const { return entries_[entry].request; }
    const PollStatistics& statistics(size_t entry) const { return entries_[entry].statistics; }
    /// The last response of @p entry (normal or exception); empty before the first.
    ResponseView response(size_t entry) const
    {
        return ResponseView(entries_[entry].response, entries_[entry].responseLength);
    }

private:
    struct Entry {
        Request request;
        uint64_t periodNs = 0;
        uint64_t dueNs = 0;
        PollStatistics statistics;
        size_t responseLength = 0;
        uint8_t response[kMaxPduLength] = {};
    };

    PollStep record(const StationStep& masterStep, uint64_t nowNs)
    {
        PollStep step;
        static_cast<StationStep&>(step) = masterStep;
        if (!masterStep.completed) {
            return step;
        }
        Entry& entry = entries_[current_];
        step.entry = current_;
        PollStatistics& statistics = entry.statistics;
        statistics.lastError = masterStep.error;
        statistics.lastException = masterStep.exception;
        statistics.lastCompletedNs = nowNs;
        switch (masterStep.error) {
        case ModbusError::Ok:
            ++statistics.successes;
            statistics.lastSuccessNs = nowNs;
            break;
        case ModbusError::ExceptionResponse: ++statistics.exceptions; break;
        case ModbusError::Timeout: ++statistics.timeouts; break;
        default: ++statistics.errors; break;
        }
        const ResponseView response = master_->response();
        entry.responseLength = response.length();
        for (size_t i = 0; i < response.length(); ++i) {
            entry.response[i] = response.pdu()[i];
        }
        return step;
    }

    Master* master_;
    size_t count_ = 0;
    size_t current_ = 0;
    Entry entries_[Capacity];
};

} // namespace modbus
