// A Modbus serial-line master ([SL] 2.4.1, Figure 7): one request at a time,
// its response matched, timed and retried, as a pure state machine.
//
//     Idle ---submit---> Waiting to send ---line idle (t3.5)---> Transmitting
//     Transmitting ---onTransmitDone---> Waiting reply         (unicast)
//                                     -> Turnaround delay       (broadcast)
//     Waiting reply ---matching response or exception---> Idle, completed
//                   ---frame from another unit---------> ignored, keeps waiting
//                   ---malformed response or time-out--> retry, or Idle with the error
//     Turnaround delay ---delay over---> Idle, completed with Ok
//
// The response time-out runs from the end of the request's transmission; a
// response whose first byte arrived in time is waited for until its end. A
// malformed response (wrong byte count, echo or function) counts as a failed
// attempt like a time-out, since [SL] 2.4.1 allows a retry "in case of an
// error detected on the frame"; an exception response is an answer and ends
// the transaction. Retries resend the same ADU.
#pragma once

#include <modbus/ModbusResult.hpp>
#include <modbus/Request.hpp>
#include <modbus/Response.hpp>
#include <modbus/StationStep.hpp>
#include <modbus/Transport.hpp>

namespace modbus {

struct MasterConfig {
    /// The longest retry count accepted: more only hides a dead slave longer.
    static constexpr uint8_t kMaxRetries = 15;
    /// The longest time-out or delay accepted, one minute.
    static constexpr uint64_t kMaxDelayNs = 60000000000ull;

    /// How long to wait for a response after a request ([SL] 2.4.1); the
    /// specification leaves it to the application, typically 1 s at 9600 baud.
    uint64_t responseTimeoutNs = 1000000000ull;
    /// The silence after a broadcast before the next request, so that every
    /// slave can execute it ([SL] 2.4.1: typically 100 to 200 ms).
    uint64_t turnaroundDelayNs = 100000000ull;
    /// Transmissions after the first when an attempt fails.
    uint8_t retries = 2;

    /// InvalidConfiguration for a time-out or delay of 0 or above kMaxDelayNs,
    /// or more than kMaxRetries retries.
    ModbusError validate() const;
};

class Master {
public:
    enum class State : uint8_t { Idle, WaitingToSend, Transmitting, WaitingReply, Turnaround };

    struct Counters {
        uint32_t transactions = 0;      ///< Requests submitted and accepted.
        uint32_t transmissions = 0;     ///< ADUs handed to the line, retries included.
        uint32_t responses = 0;         ///< Matching responses, exceptions included.
        uint32_t exceptions = 0;        ///< Exception responses.
        uint32_t timeouts = 0;          ///< Attempts that ended without a response.
        uint32_t invalidResponses = 0;  ///< Attempts that ended with a malformed response.
        uint32_t failures = 0;          ///< Transactions that ended with an error other than an exception.
        uint32_t foreignFrames = 0;     ///< Frames from other units, or when no response was due.
    };

    /// A placeholder; only a target for assignment.
    Master() = default;

    /// A master on @p transport (which outlives it) with @p config, or why not.
    static ModbusResult<Master> create(Transport& transport, const MasterConfig& config);

    /// Starts a transaction for @p request at @p nowNs: the step transmits its
    /// ADU now if the line is idle, or a later poll() does. Rejected with Busy
    /// while a transaction runs, or with the transport's reason when the
    /// request cannot be framed.
    StationStep submit(const Request& request, uint64_t nowNs);

    /// Bytes received from the line at @p nowNs.
    StationStep onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs);

    /// Lets time pass: ends frames, runs the time-out and the turnaround
    /// delay, and sends a request waiting for the line.
    StationStep poll(uint64_t nowNs);

    /// The request handed over by the last step has left the line at
    /// @p nowNs; rejected with NotExpected when none was being sent.
    StationStep onTransmitDone(uint64_t nowNs);

    /// When poll() has something to do, or ~0.
    uint64_t nextDeadlineNs() const;

    /// Whether a request may be submitted.
    bool idle() const { return state_ == State::Idle; }
    State state() const { return state_; }
    /// The response of the last transaction that ended with a response
    /// (exceptions included); valid until the next submit().
    ResponseView response() const { return ResponseView(response_, responseLength_); }
    const Counters& counters() const { return counters_; }
    const MasterConfig& config() const { return config_; }

private:
    StationStep handleFrames(StationStep step);
    StationStep failAttempt(StationStep step, ModbusError error);
    StationStep sendIfReady(StationStep step);
    StationStep complete(StationStep step, ModbusError error, ExceptionCode exception);

    Transport* transport_ = nullptr;
    MasterConfig config_;
    State state_ = State::Idle;
    Request request_;
    uint8_t attempts_ = 0;          // transmissions of the current request
    uint64_t deadline_ = 0;         // end of the response time-out or turnaround delay
    size_t aduLength_ = 0;
    size_t responseLength_ = 0;
    Counters counters_;
    uint8_t adu_[kMaxAduLength] = {};
    uint8_t response_[kMaxPduLength] = {};
};

} // namespace modbus
