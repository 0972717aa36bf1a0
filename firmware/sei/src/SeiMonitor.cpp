// The node's monitoring stream (SeiMonitor.hpp).
#include <sei/SeiMonitor.hpp>

namespace sei {

namespace {

constexpr uint64_t kNsPerMs = 1'000'000;
constexpr uint64_t kNsPerSecond = 1'000'000'000;
constexpr uint32_t kMaxLostPerFrame = 0xFFFF;

} // namespace

uint8_t SeiMonitor::configure(const SeiMessage& request, const MonitorTarget& from, uint64_t nowNs)
{
    if (request.leaseSeconds == 0) {
        // Stopping a stream that does not run is done already: a host that
        // stops twice, or after the lease ran out, is told so.
        if (running_) {
            end(MonitorEndReason::Stopped);
        }
        return kOk;
    }
    if (request.periodMs < kMinPeriodMs || request.periodMs > kMaxPeriodMs ||
        request.leaseSeconds > kMaxLeaseSeconds || request.channelCount > kSeiMaxMonitorChannels) {
        return kInvalidArgument;
    }
    // Every publisher first, so that a refusal changes nothing.
    Channel opened[kSeiMaxMonitorChannels];
    for (uint8_t i = 0; i < request.channelCount; ++i) {
        const SeiMonitorChannel& asked = request.channels[i];
        if (static_cast<size_t>(asked.offset) + seiSampleSize(asked.format) > kSeiPageSize) {
            for (uint8_t j = 0; j < i; ++j) {
                pages_.close(opened[j].subscription);
            }
            return kInvalidArgument;
        }
        const uint8_t status = pages_.open(asked.publisher, opened[i].subscription);
        if (status != kOk) {
            for (uint8_t j = 0; j < i; ++j) {
                pages_.close(opened[j].subscription);
            }
            return status;
        }
        opened[i].offset = asked.offset;
        opened[i].format = asked.format;
    }

    // The same host on the same interface renews (or changes) its stream;
    // any other host takes it over, and the one before is told.
    const bool renewal = running_ && target_.host == from.host && target_.interface == from.interface;
    if (running_ && !renewal) {
        end(MonitorEndReason::Replaced);
    }
    const bool keepPhase = renewal && periodMs_ == request.periodMs && channelCount_ != 0;
    closeChannels();
    for (uint8_t i = 0; i < request.channelCount; ++i) {
        channels_[i] = opened[i];
    }
    channelCount_ = request.channelCount;
    if (!renewal) {
        logSequence_ = 0;
        pendingLost_ = 0;
    }
    target_ = from;
    periodMs_ = request.periodMs;
    leaseEndNs_ = nowNs + static_cast<uint64_t>(request.leaseSeconds) * kNsPerSecond;
    // A renewal keeps the sampling schedule, so the host sees one period
    // between samples whenever it renews; anything else samples at once.
    if (channelCount_ == 0) {
        nextSampleNs_ = kNoDeadline;
    } else if (!keepPhase) {
        nextSampleNs_ = nowNs;
    }

    const bool wantLog = (request.monitorFlags & kSeiMonitorLog) != 0;
    if (wantLog && !logging_) {
        log_.capture(true);
        nextLogNs_ = nowNs;
    } else if (!wantLog && logging_) {
        log_.capture(false);
        nextLogNs_ = kNoDeadline;
    }
    logging_ = wantLog;
    running_ = true;
    return kOk;
}

void SeiMonitor::poll(uint64_t nowNs)
{
    if (!running_) {
        return;
    }
    if (nowNs >= leaseEndNs_) {
        end(MonitorEndReason::LeaseExpired);
        return;
    }
    if (channelCount_ != 0 && nowNs >= nextSampleNs_) {
        sample(nowNs);
    }
    if (logging_ && nowNs >= nextLogNs_) {
        sendLog(nowNs);
    }
}

uint64_t SeiMonitor::nextDeadlineNs() const
{
    if (!running_) {
        return kNoDeadline;
    }
    uint64_t deadline = leaseEndNs_;
    if (channelCount_ != 0 && nextSampleNs_ < deadline) {
        deadline = nextSampleNs_;
    }
    if (logging_ && nextLogNs_ < deadline) {
        deadline = nextLogNs_;
    }
    return deadline;
}

bool SeiMonitor::sendFrame(const MonitorFrame& frame)
{
    uint8_t bytes[kMonitorFrameMax];
    const size_t length = frame.encode(bytes);
    if (length == 0) {
        return false;
    }
    if (!sender_.send(target_, bytes, static_cast<uint8_t>(length))) {
        ++framesRefused_;
        return false;
    }
    ++framesSent_;
    return true;
}

void SeiMonitor::end(MonitorEndReason reason)
{
    MonitorFrame frame;
    frame.kind = MonitorFrameKind::End;
    frame.reason = reason;
    // Unacknowledged like every frame of the stream: a host that misses it
    // still sees the samples stop.
    (void)sendFrame(frame);
    closeChannels();
    if (logging_) {
        log_.capture(false);
    }
    running_ = false;
    logging_ = false;
    pendingLost_ = 0;
    nextSampleNs_ = kNoDeadline;
    nextLogNs_ = kNoDeadline;
}

void SeiMonitor::closeChannels()
{
    for (uint8_t i = 0; i < channelCount_; ++i) {
        pages_.close(channels_[i].subscription);
    }
    channelCount_ = 0;
}

void SeiMonitor::sample(uint64_t nowNs)
{
    const uint16_t timeMs = static_cast<uint16_t>(nowNs / kNsPerMs);
    for (uint8_t i = 0; i < channelCount_; ++i) {
        uint8_t page[kSeiPageSize];
        if (!pages_.read(channels_[i].subscription, page)) {
            // Nothing published yet: no value to send, rather than a zero
            // the host would plot as if it had been written.
            continue;
        }
        MonitorFrame frame;
        frame.kind = MonitorFrameKind::Sample;
        frame.channel = i;
        frame.timeMs = timeMs;
        frame.value = monitorSampleValue(page, channels_[i].offset, channels_[i].format);
        (void)sendFrame(frame);
    }
    const uint64_t period = static_cast<uint64_t>(periodMs_) * kNsPerMs;
    nextSampleNs_ += period;
    if (nextSampleNs_ <= nowNs) {
        // The task was held up for more than a period: the missed samples
        // are gone, and a burst of stale ones would only crowd the bus.
        nextSampleNs_ = nowNs + period;
    }
}

void SeiMonitor::sendLog(uint64_t nowNs)
{
    for (size_t frames = 0; frames < kMaxLogFramesPerWake; ++frames) {
        if (pendingLost_ == 0) {
            uint8_t text[kMonitorLogText];
            const size_t length = log_.peek(text, sizeof text);
            if (length != 0) {
                MonitorFrame frame;
                frame.kind = MonitorFrameKind::Log;
                frame.sequence = logSequence_;
                frame.textLength = static_cast<uint8_t>(length);
                for (size_t i = 0; i < length; ++i) {
                    frame.text[i] = text[i];
                }
                if (!sendFrame(frame)) {
                    break; // The bytes stay in the ring for the next wake.
                }
                log_.consume(length);
                ++logSequence_;
                continue;
            }
            pendingLost_ = static_cast<uint16_t>(log_.takeLost(kMaxLostPerFrame));
            if (pendingLost_ == 0) {
                break;
            }
        }
        MonitorFrame lost;
        lost.kind = MonitorFrameKind::Lost;
        lost.lostBytes = pendingLost_;
        if (!sendFrame(lost)) {
            break;
        }
        pendingLost_ = 0;
    }
    nextLogNs_ = nowNs + (log_.pending() || pendingLost_ != 0 ? kLogBusyNs : kLogIdleNs);
}

} // namespace sei
