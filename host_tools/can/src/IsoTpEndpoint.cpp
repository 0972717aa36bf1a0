#include <hostcan/IsoTpEndpoint.hpp>

#include <can/IsoTpReceiver.hpp>
#include <can/IsoTpSender.hpp>

#include <algorithm>

namespace hostcan {

namespace {

using Clock = std::chrono::steady_clock;

uint64_t nowNs()
{
    return static_cast<uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count());
}

// How long to wait for the next frame: until the state machine's deadline,
// or a little when it has none, so the loop also notices the time-outs.
std::chrono::milliseconds waitUntil(uint64_t deadlineNs, uint64_t limitNs)
{
    const uint64_t now = nowNs();
    const uint64_t until = std::min(deadlineNs, limitNs);
    if (until <= now) {
        return std::chrono::milliseconds(0);
    }
    return std::chrono::milliseconds(std::min<uint64_t>((until - now + 999'999) / 1'000'000, 100));
}

} // namespace

IsoTpOutcome isoTpSend(Transport& transport, const can::IsoTpConfig& config, const std::vector<uint8_t>& message)
{
    IsoTpOutcome outcome;
    can::LinkResult<can::IsoTpSender> created = can::IsoTpSender::create(config);
    if (!created.ok()) {
        outcome.error = created.error();
        return outcome;
    }
    can::IsoTpSender sender = created.value();
    can::IsoTpStep step = sender.start(message.data(), message.size(), nowNs());
    for (;;) {
        if (step.rejected != can::LinkError::Ok && !step.transmit && sender.idle()) {
            outcome.error = step.rejected;
            return outcome;
        }
        if (step.aborted != can::LinkError::Ok) {
            outcome.error = step.aborted;
            return outcome;
        }
        if (step.completed) {
            return outcome;
        }
        if (step.transmit) {
            if (TransportError e = transport.send(step.frame, std::chrono::milliseconds(100))) {
                outcome.transport = e;
                return outcome;
            }
            step = sender.onTransmitConfirmed(nowNs());
            continue;
        }
        TransportError error;
        const Received r = transport.receive(waitUntil(sender.nextDeadlineNs(), ~uint64_t{0}), error);
        if (error) {
            outcome.transport = error;
            return outcome;
        }
        step = r.kind == Received::Kind::Frame ? sender.onFrame(r.frame, nowNs()) : sender.poll(nowNs());
        if (step.rejected != can::LinkError::Ok && !step.transmit && !step.completed &&
            step.aborted == can::LinkError::Ok) {
            step = can::IsoTpStep{}; // A frame the standard says to ignore: keep waiting.
        }
    }
}

IsoTpOutcome isoTpReceive(Transport& transport, const can::IsoTpConfig& config,
                          std::chrono::milliseconds firstFrameTimeout)
{
    IsoTpOutcome outcome;
    std::vector<uint8_t> buffer(4095);
    can::LinkResult<can::IsoTpReceiver> created = can::IsoTpReceiver::create(config, buffer.data(), buffer.size());
    if (!created.ok()) {
        outcome.error = created.error();
        return outcome;
    }
    can::IsoTpReceiver receiver = created.value();
    const uint64_t giveUpNs = nowNs() + static_cast<uint64_t>(firstFrameTimeout.count()) * 1'000'000;
    for (;;) {
        if (receiver.idle() && nowNs() >= giveUpNs) {
            outcome.error = can::LinkError::TimeoutCr;
            return outcome;
        }
        TransportError error;
        const uint64_t deadline = receiver.idle() ? giveUpNs : receiver.nextDeadlineNs();
        const Received r = transport.receive(waitUntil(deadline, deadline), error);
        if (error) {
            outcome.transport = error;
            return outcome;
        }
        const can::IsoTpStep step =
            r.kind == Received::Kind::Frame ? receiver.onFrame(r.frame, nowNs()) : receiver.poll(nowNs());
        if (step.transmit) {
            if (TransportError e = transport.send(step.frame, std::chrono::milliseconds(100))) {
                outcome.transport = e;
                return outcome;
            }
        }
        if (step.completed) {
            outcome.message.assign(receiver.buffer(), receiver.buffer() + step.length);
            return outcome;
        }
        if (step.aborted != can::LinkError::Ok) {
            outcome.error = step.aborted;
            return outcome;
        }
    }
}

} // namespace hostcan
