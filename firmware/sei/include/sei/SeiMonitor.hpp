// The node's monitoring stream (docs/protocols/monitor.md): what the
// configuration protocol's Monitor command starts, renews, replaces and
// stops, and what frames the stream sends when. Pure code: the
// publications it samples, the console copy it reads and the bus it sends
// on are behind the three small interfaces below, which the system
// engineering interface agent's task (firmware/flash/src/FlashService.cpp)
// implements on the DSM agent, the console's ring and the CAN link, and
// the host tests implement in memory.
#pragma once

#include <sei/MonitorFrame.hpp>
#include <sei/SeiMessage.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

/// Where a stream goes: the interface and the host's CAN node number the
/// Monitor request came from, and the priority it came at.
struct MonitorTarget {
    uint8_t interface = 0xFF;
    uint8_t host = 0xFF;
    uint8_t priority = 31;

    bool operator==(const MonitorTarget& other) const
    {
        return interface == other.interface && host == other.host && priority == other.priority;
    }
};

/// The node's publications as the stream samples them.
class MonitorPages {
public:
    /// Opens a subscription to @p publisher, a publisher of this node, for
    /// the agent's task: 0 with @p subscription, or the kernel's
    /// dcos::Status value that refused it.
    virtual uint8_t open(uint32_t publisher, uint32_t& subscription) = 0;
    virtual void close(uint32_t subscription) = 0;
    /// The publication's current page, at once; false when there is none
    /// (never written, or the publisher was deleted).
    virtual bool read(uint32_t subscription, uint8_t (&page)[kSeiPageSize]) = 0;

protected:
    ~MonitorPages() = default;
};

/// The copy of the console's output (a LogRing behind whatever guards it).
class MonitorLog {
public:
    /// Starts (@p on) or stops copying the console's output; starting
    /// forgets what an earlier stream left.
    virtual void capture(bool on) = 0;
    virtual size_t peek(uint8_t* out, size_t max) = 0;
    virtual void consume(size_t count) = 0;
    /// LogRing::takeLost.
    virtual uint32_t takeLost(uint32_t max) = 0;
    /// Whether anything waits: bytes, or a gap to report.
    virtual bool pending() = 0;

protected:
    ~MonitorLog() = default;
};

/// The bus.
class MonitorSender {
public:
    /// Sends one frame of @p length bytes to @p target, unacknowledged;
    /// false when the interface could not take it now (its queue is full).
    virtual bool send(const MonitorTarget& target, const uint8_t* data, uint8_t length) = 0;

protected:
    ~MonitorSender() = default;
};

class SeiMonitor {
public:
    /// The values Monitor takes (else InvalidArgument).
    static constexpr uint16_t kMinPeriodMs = 10;
    static constexpr uint16_t kMaxPeriodMs = 60000;
    static constexpr uint16_t kMaxLeaseSeconds = 3600;
    /// How often the console's copy is looked at while it holds nothing,
    /// and while it holds more than one wake sends.
    static constexpr uint64_t kLogIdleNs = 20'000'000;
    static constexpr uint64_t kLogBusyNs = 10'000'000;
    /// The Log frames one wake sends at most: a chatty console fills its
    /// ring and reports the loss instead of holding the agent's task, whose
    /// configuration protocol shares the wake, or filling the interface's
    /// transmit queue, which the protocol's replies need too.
    static constexpr size_t kMaxLogFramesPerWake = 4;
    static constexpr uint64_t kNoDeadline = UINT64_MAX;

    /// The kernel's status values this class returns (dcos::Status, whose
    /// header this portable code does not need).
    static constexpr uint8_t kOk = 0;
    static constexpr uint8_t kInvalidArgument = 6;

    SeiMonitor(MonitorPages& pages, MonitorLog& log, MonitorSender& sender)
        : pages_(pages), log_(log), sender_(sender)
    {
    }

    /// Applies a Monitor @p request that came from @p from at @p nowNs:
    /// starts the stream, renews or replaces it (a request from another host
    /// ends the old one's with End Replaced), or with lease 0 stops it (End
    /// Stopped). Every channel's publisher is opened before anything
    /// changes, so a refused request leaves the stream as it was. Returns
    /// the kernel's status value: 0, InvalidArgument for a period or lease
    /// out of range, or the refusal of a channel's publisher.
    uint8_t configure(const SeiMessage& request, const MonitorTarget& from, uint64_t nowNs);

    /// Does what is due at @p nowNs: ends a stream whose lease ran out,
    /// samples the channels once a period, sends console output.
    void poll(uint64_t nowNs);

    /// When poll() has work next, kNoDeadline when no stream runs.
    uint64_t nextDeadlineNs() const;

    bool running() const { return running_; }
    const MonitorTarget& target() const { return target_; }
    uint8_t channelCount() const { return channelCount_; }
    uint16_t periodMs() const { return periodMs_; }
    bool logging() const { return logging_; }
    uint64_t leaseEndNs() const { return leaseEndNs_; }

    /// Frames sent, and those the interface refused (counted, not retried:
    /// a sample is worth something only in its period).
    uint32_t framesSent() const { return framesSent_; }
    uint32_t framesRefused() const { return framesRefused_; }

private:
    struct Channel {
        uint32_t subscription = 0;
        uint8_t offset = 0;
        SeiSampleFormat format = SeiSampleFormat::U8;
    };

    bool sendFrame(const MonitorFrame& frame);
    void end(MonitorEndReason reason);
    void closeChannels();
    void sample(uint64_t nowNs);
    void sendLog(uint64_t nowNs);

    MonitorPages& pages_;
    MonitorLog& log_;
    MonitorSender& sender_;

    bool running_ = false;
    MonitorTarget target_;
    Channel channels_[kSeiMaxMonitorChannels];
    uint8_t channelCount_ = 0;
    uint16_t periodMs_ = 0;
    bool logging_ = false;
    uint8_t logSequence_ = 0;
    uint64_t leaseEndNs_ = 0;
    uint64_t nextSampleNs_ = kNoDeadline;
    uint64_t nextLogNs_ = kNoDeadline;
    // Console bytes dropped whose Lost frame the interface has not taken
    // yet: sent before any later text, so the gap stays where it was.
    uint16_t pendingLost_ = 0;
    uint32_t framesSent_ = 0;
    uint32_t framesRefused_ = 0;
};

} // namespace sei
