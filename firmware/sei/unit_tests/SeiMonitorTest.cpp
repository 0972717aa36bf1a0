// The node's monitoring stream (docs/protocols/monitor.md) on publications,
// a console ring and a bus in memory: the lease, its renewal and its end,
// the period, stop and replace, the refusals that leave the stream as it
// was, the console ring's overflow reported by a Lost frame where the
// bytes fell, and the bound on frames per wake.
#include <sei/LogRing.hpp>
#include <sei/SeiMonitor.hpp>

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

using sei::MonitorEndReason;
using sei::MonitorFrame;
using sei::MonitorFrameKind;
using sei::MonitorTarget;
using sei::SeiMonitor;
using sei::SeiSampleFormat;

constexpr uint64_t kMs = 1'000'000;
constexpr uint64_t kSecond = 1'000'000'000;
constexpr uint8_t kInvalidId = 1;
constexpr uint8_t kWrongType = 3;

// Publishers by id, each with a page that a test writes; subscriptions
// counted so that a test sees every one closed.
class Pages final : public sei::MonitorPages {
public:
    uint8_t open(uint32_t publisher, uint32_t& subscription) override
    {
        if (refusals.count(publisher) != 0) {
            return refusals[publisher];
        }
        subscription = nextSubscription++;
        subscribed[subscription] = publisher;
        return 0;
    }
    void close(uint32_t subscription) override
    {
        ASSERT_EQ(subscribed.count(subscription), 1u) << "closed twice or never opened";
        subscribed.erase(subscription);
    }
    bool read(uint32_t subscription, uint8_t (&page)[sei::kSeiPageSize]) override
    {
        const auto found = pages.find(subscribed.at(subscription));
        if (found == pages.end()) {
            return false;
        }
        for (size_t i = 0; i < sei::kSeiPageSize; ++i) {
            page[i] = found->second[i];
        }
        return true;
    }

    void write(uint32_t publisher, int32_t value)
    {
        std::vector<uint8_t>& page = pages[publisher];
        page.assign(sei::kSeiPageSize, 0);
        for (size_t i = 0; i < 4; ++i) {
            page[i] = static_cast<uint8_t>(static_cast<uint32_t>(value) >> (8 * i));
        }
    }

    std::map<uint32_t, std::vector<uint8_t>> pages;
    std::map<uint32_t, uint8_t> refusals;
    std::map<uint32_t, uint32_t> subscribed;
    uint32_t nextSubscription = 100;
};

// The ring the console writes into, as the node's adapter wraps it.
class Log final : public sei::MonitorLog {
public:
    void capture(bool on) override
    {
        capturing = on;
        if (on) {
            ring.clear();
        }
    }
    size_t peek(uint8_t* out, size_t max) override { return ring.peek(out, max); }
    void consume(size_t count) override { ring.consume(count); }
    uint32_t takeLost(uint32_t max) override { return ring.takeLost(max); }
    bool pending() override { return ring.pending(); }

    void print(const std::string& text)
    {
        if (capturing) {
            for (const char c : text) {
                (void)ring.put(static_cast<uint8_t>(c));
            }
        }
    }

    sei::LogRing<64> ring;
    bool capturing = false;
};

struct Sent {
    MonitorTarget to;
    MonitorFrame frame;
};

class Bus final : public sei::MonitorSender {
public:
    bool send(const MonitorTarget& target, const uint8_t* data, uint8_t length) override
    {
        if (full) {
            return false;
        }
        MonitorFrame frame;
        EXPECT_TRUE(MonitorFrame::decode(data, length, frame)) << "the node sent a frame its own decoder refuses";
        sent.push_back({target, frame});
        return true;
    }

    std::vector<Sent> take()
    {
        std::vector<Sent> taken;
        taken.swap(sent);
        return taken;
    }

    std::vector<Sent> sent;
    bool full = false;
};

sei::SeiMessage monitorRequest(uint16_t leaseSeconds, uint16_t periodMs, std::vector<uint32_t> publishers,
                               bool log = false, SeiSampleFormat format = SeiSampleFormat::I32)
{
    sei::SeiMessage request;
    request.command = sei::SeiCommand::Monitor;
    request.leaseSeconds = leaseSeconds;
    request.periodMs = periodMs;
    request.monitorFlags = log ? sei::kSeiMonitorLog : 0;
    request.channelCount = static_cast<uint8_t>(publishers.size());
    for (size_t i = 0; i < publishers.size(); ++i) {
        request.channels[i].publisher = publishers[i];
        request.channels[i].offset = 0;
        request.channels[i].format = format;
    }
    return request;
}

class SeiMonitorTest : public ::testing::Test {
protected:
    // Polls at every deadline up to @p untilNs, as the agent's task wakes.
    void runUntil(uint64_t untilNs)
    {
        for (int guard = 0; guard < 100000; ++guard) {
            const uint64_t deadline = monitor.nextDeadlineNs();
            if (deadline > untilNs) {
                now = untilNs;
                return;
            }
            now = deadline > now ? deadline : now;
            monitor.poll(now);
        }
        FAIL() << "the deadline never moved";
    }

    std::vector<Sent> ofKind(const std::vector<Sent>& frames, MonitorFrameKind kind)
    {
        std::vector<Sent> out;
        for (const Sent& s : frames) {
            if (s.frame.kind == kind) {
                out.push_back(s);
            }
        }
        return out;
    }

    Pages pages;
    Log log;
    Bus bus;
    SeiMonitor monitor{pages, log, bus};
    MonitorTarget host{0, 254, 31};
    MonitorTarget otherHost{0, 200, 5};
    uint64_t now = 1 * kSecond;
};

TEST_F(SeiMonitorTest, SamplesOncePerPeriodWithTheNodeTimeInMilliseconds)
{
    pages.write(0x10, 42);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {0x10}), host, now), 0);
    EXPECT_TRUE(monitor.running());
    runUntil(now + 1 * kSecond);
    const std::vector<Sent> samples = ofKind(bus.take(), MonitorFrameKind::Sample);
    // At once, then every 100 ms: 0, 100, ..., 1000 ms.
    ASSERT_EQ(samples.size(), 11u);
    for (size_t i = 0; i < samples.size(); ++i) {
        EXPECT_EQ(samples[i].frame.timeMs, static_cast<uint16_t>(1000 + 100 * i));
        EXPECT_EQ(samples[i].frame.value, 42);
        EXPECT_EQ(samples[i].frame.channel, 0);
        EXPECT_EQ(samples[i].to, host);
    }
}

TEST_F(SeiMonitorTest, TheTimeWrapsModulo65536Milliseconds)
{
    pages.write(0x10, 1);
    now = 65535 * kMs;
    ASSERT_EQ(monitor.configure(monitorRequest(10, 10, {0x10}), host, now), 0);
    runUntil(now + 10 * kMs);
    const std::vector<Sent> samples = ofKind(bus.take(), MonitorFrameKind::Sample);
    ASSERT_EQ(samples.size(), 2u);
    EXPECT_EQ(samples[0].frame.timeMs, 65535);
    EXPECT_EQ(samples[1].frame.timeMs, 9);
}

TEST_F(SeiMonitorTest, EveryChannelEveryPeriodAndNoValueBeforeTheFirstWrite)
{
    pages.write(0x10, -5);
    pages.write(0x20, 7);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 50, {0x10, 0x20, 0x30}), host, now), 0);
    runUntil(now + 100 * kMs);
    const std::vector<Sent> samples = ofKind(bus.take(), MonitorFrameKind::Sample);
    // Three periods, two channels written: publisher 0x30 was never written.
    ASSERT_EQ(samples.size(), 6u);
    EXPECT_EQ(samples[0].frame.channel, 0);
    EXPECT_EQ(samples[0].frame.value, -5);
    EXPECT_EQ(samples[1].frame.channel, 1);
    EXPECT_EQ(samples[1].frame.value, 7);
    pages.write(0x30, 9);
    runUntil(now + 50 * kMs);
    EXPECT_EQ(ofKind(bus.take(), MonitorFrameKind::Sample).size(), 3u);
}

TEST_F(SeiMonitorTest, TheLeaseEndsTheStreamAndClosesEverySubscription)
{
    pages.write(0x10, 1);
    const uint64_t start = now;
    ASSERT_EQ(monitor.configure(monitorRequest(2, 500, {0x10}, true), host, now), 0);
    EXPECT_EQ(pages.subscribed.size(), 1u);
    EXPECT_TRUE(log.capturing);
    runUntil(start + 2 * kSecond - 1);
    EXPECT_TRUE(monitor.running());
    runUntil(start + 2 * kSecond);
    EXPECT_FALSE(monitor.running());
    const std::vector<Sent> frames = bus.take();
    ASSERT_FALSE(frames.empty());
    EXPECT_EQ(frames.back().frame.kind, MonitorFrameKind::End);
    EXPECT_EQ(frames.back().frame.reason, MonitorEndReason::LeaseExpired);
    EXPECT_EQ(frames.back().to, host);
    EXPECT_TRUE(pages.subscribed.empty());
    EXPECT_FALSE(log.capturing);
    EXPECT_EQ(monitor.nextDeadlineNs(), SeiMonitor::kNoDeadline);
    runUntil(start + 10 * kSecond);
    EXPECT_TRUE(bus.take().empty()) << "nothing after the end";
}

TEST_F(SeiMonitorTest, ARenewalExtendsTheLeaseAndKeepsTheSchedule)
{
    pages.write(0x10, 1);
    const uint64_t start = now;
    ASSERT_EQ(monitor.configure(monitorRequest(3, 100, {0x10}), host, now), 0);
    // The host renews every third of the lease, for ten seconds.
    for (int renewal = 1; renewal <= 10; ++renewal) {
        runUntil(start + renewal * kSecond + 30 * kMs);
        ASSERT_EQ(monitor.configure(monitorRequest(3, 100, {0x10}), host, now), 0);
        EXPECT_EQ(pages.subscribed.size(), 1u) << "a renewal closes the subscriptions it replaces";
    }
    runUntil(start + 10 * kSecond + 30 * kMs);
    EXPECT_TRUE(monitor.running());
    const std::vector<Sent> frames = bus.take();
    EXPECT_TRUE(ofKind(frames, MonitorFrameKind::End).empty());
    const std::vector<Sent> samples = ofKind(frames, MonitorFrameKind::Sample);
    ASSERT_EQ(samples.size(), 101u);
    for (size_t i = 1; i < samples.size(); ++i) {
        EXPECT_EQ(static_cast<uint16_t>(samples[i].frame.timeMs - samples[i - 1].frame.timeMs), 100) << i;
    }
    // Without renewal it ends three seconds after the last one.
    runUntil(start + 13 * kSecond + 30 * kMs);
    EXPECT_FALSE(monitor.running());
    EXPECT_EQ(ofKind(bus.take(), MonitorFrameKind::End).size(), 1u);
}

TEST_F(SeiMonitorTest, LeaseZeroStopsTheStream)
{
    pages.write(0x10, 1);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {0x10}, true), host, now), 0);
    runUntil(now + 250 * kMs);
    bus.take();
    ASSERT_EQ(monitor.configure(monitorRequest(0, 0, {}), host, now), 0);
    EXPECT_FALSE(monitor.running());
    const std::vector<Sent> frames = bus.take();
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].frame.kind, MonitorFrameKind::End);
    EXPECT_EQ(frames[0].frame.reason, MonitorEndReason::Stopped);
    EXPECT_TRUE(pages.subscribed.empty());
    EXPECT_FALSE(log.capturing);
    // Stopping what does not run is done already, and says nothing.
    EXPECT_EQ(monitor.configure(monitorRequest(0, 0, {}), host, now), 0);
    EXPECT_TRUE(bus.take().empty());
}

TEST_F(SeiMonitorTest, AnotherHostReplacesTheStreamAndTheFirstIsTold)
{
    pages.write(0x10, 1);
    pages.write(0x20, 2);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {0x10}), host, now), 0);
    runUntil(now + 150 * kMs);
    bus.take();
    ASSERT_EQ(monitor.configure(monitorRequest(10, 200, {0x20}), otherHost, now), 0);
    const std::vector<Sent> told = bus.take();
    ASSERT_EQ(told.size(), 1u);
    EXPECT_EQ(told[0].to, host);
    EXPECT_EQ(told[0].frame.kind, MonitorFrameKind::End);
    EXPECT_EQ(told[0].frame.reason, MonitorEndReason::Replaced);
    EXPECT_EQ(pages.subscribed.size(), 1u);
    EXPECT_EQ(pages.subscribed.begin()->second, 0x20u);
    runUntil(now + 400 * kMs);
    const std::vector<Sent> samples = bus.take();
    ASSERT_EQ(samples.size(), 3u);
    for (const Sent& s : samples) {
        EXPECT_EQ(s.to, otherHost) << "the new host's priority and number";
        EXPECT_EQ(s.frame.value, 2);
    }
}

TEST_F(SeiMonitorTest, ARequestReplacesTheWholeChannelSet)
{
    pages.write(0x10, 1);
    pages.write(0x20, 2);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {0x10, 0x20}), host, now), 0);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {0x20}), host, now), 0);
    EXPECT_EQ(monitor.channelCount(), 1);
    EXPECT_EQ(pages.subscribed.size(), 1u);
    runUntil(now + 100 * kMs);
    for (const Sent& s : bus.take()) {
        EXPECT_EQ(s.frame.value, 2);
    }
}

TEST_F(SeiMonitorTest, RefusalsLeaveTheStreamAsItWas)
{
    pages.write(0x10, 1);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {0x10}), host, now), 0);
    EXPECT_EQ(monitor.configure(monitorRequest(10, 9, {0x10}), host, now), SeiMonitor::kInvalidArgument);
    EXPECT_EQ(monitor.configure(monitorRequest(10, 60001, {0x10}), host, now), SeiMonitor::kInvalidArgument);
    EXPECT_EQ(monitor.configure(monitorRequest(3601, 100, {0x10}), host, now), SeiMonitor::kInvalidArgument);
    pages.refusals[0x99] = kInvalidId;
    pages.refusals[0x98] = kWrongType;
    EXPECT_EQ(monitor.configure(monitorRequest(10, 100, {0x10, 0x99}), host, now), kInvalidId);
    EXPECT_EQ(monitor.configure(monitorRequest(10, 100, {0x98}), otherHost, now), kWrongType);
    EXPECT_TRUE(monitor.running());
    EXPECT_EQ(monitor.target(), host) << "a refused request from another host takes nothing over";
    EXPECT_EQ(pages.subscribed.size(), 1u) << "the refused request's own subscriptions are closed";
    EXPECT_TRUE(ofKind(bus.take(), MonitorFrameKind::End).empty());
    // The limits themselves are taken.
    EXPECT_EQ(monitor.configure(monitorRequest(3600, 10, {0x10}), host, now), 0);
    EXPECT_EQ(monitor.configure(monitorRequest(1, 60000, {0x10}), host, now), 0);
    // Nothing refused starts a stream that did not run.
    SeiMonitor fresh{pages, log, bus};
    EXPECT_EQ(fresh.configure(monitorRequest(10, 5, {0x10}), host, now), SeiMonitor::kInvalidArgument);
    EXPECT_FALSE(fresh.running());
}

TEST_F(SeiMonitorTest, AHeldUpTaskSkipsTheMissedSamplesInsteadOfABurst)
{
    pages.write(0x10, 1);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {0x10}), host, now), 0);
    monitor.poll(now);
    bus.take();
    now += 550 * kMs;
    monitor.poll(now);
    EXPECT_EQ(bus.take().size(), 1u);
    EXPECT_EQ(monitor.nextDeadlineNs(), now + 100 * kMs);
}

TEST_F(SeiMonitorTest, ConsoleOutputGoesInOrderWithASequence)
{
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {}, true), host, now), 0);
    log.print("hello, world\r\n");
    runUntil(now + 100 * kMs);
    const std::vector<Sent> frames = ofKind(bus.take(), MonitorFrameKind::Log);
    std::string text;
    for (size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(frames[i].frame.sequence, i);
        text.append(frames[i].frame.text, frames[i].frame.text + frames[i].frame.textLength);
    }
    EXPECT_EQ(text, "hello, world\r\n");
    EXPECT_EQ(frames.size(), 3u);
}

TEST_F(SeiMonitorTest, NoMoreThanTheBoundOfLogFramesPerWake)
{
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {}, true), host, now), 0);
    log.print(std::string(60, 'x'));
    monitor.poll(now);
    EXPECT_EQ(bus.take().size(), SeiMonitor::kMaxLogFramesPerWake);
    EXPECT_EQ(monitor.nextDeadlineNs(), now + SeiMonitor::kLogBusyNs) << "soon again while text waits";
    runUntil(now + 100 * kMs);
    size_t bytes = 0;
    for (const Sent& s : bus.take()) {
        bytes += s.frame.textLength;
    }
    EXPECT_EQ(bytes + SeiMonitor::kMaxLogFramesPerWake * sei::kMonitorLogText, 60u);
}

TEST_F(SeiMonitorTest, ARingOverflowIsReportedWhereTheBytesFell)
{
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {}, true), host, now), 0);
    // 64 bytes fit; 36 more fall; then, while the ring still holds the
    // first ones, more are dropped, not put after the gap.
    std::string first(64, 'a');
    log.print(first + std::string(36, 'b'));
    log.print("cc");
    runUntil(now + 200 * kMs);
    log.print("after");
    runUntil(now + 100 * kMs);
    std::string text;
    uint32_t lost = 0;
    bool lostBeforeAfter = false;
    uint8_t expectedSequence = 0;
    for (const Sent& s : bus.take()) {
        if (s.frame.kind == MonitorFrameKind::Log) {
            EXPECT_EQ(s.frame.sequence, expectedSequence++);
            text.append(s.frame.text, s.frame.text + s.frame.textLength);
        } else if (s.frame.kind == MonitorFrameKind::Lost) {
            EXPECT_EQ(text, first) << "the gap comes right after what the ring held";
            lost += s.frame.lostBytes;
            lostBeforeAfter = true;
        }
    }
    EXPECT_TRUE(lostBeforeAfter);
    EXPECT_EQ(lost, 38u);
    EXPECT_EQ(text, first + "after");
}

TEST_F(SeiMonitorTest, ABusThatRefusesLosesNoConsoleText)
{
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {}, true), host, now), 0);
    log.print("abcdefghij");
    bus.full = true;
    runUntil(now + 50 * kMs);
    EXPECT_GT(monitor.framesRefused(), 0u);
    bus.full = false;
    runUntil(now + 50 * kMs);
    std::string text;
    for (const Sent& s : bus.take()) {
        text.append(s.frame.text, s.frame.text + s.frame.textLength);
    }
    EXPECT_EQ(text, "abcdefghij");
}

TEST_F(SeiMonitorTest, ConsoleOutputIsCapturedOnlyWhileALogStreamRuns)
{
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {}, false), host, now), 0);
    EXPECT_FALSE(log.capturing);
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {}, true), host, now), 0);
    EXPECT_TRUE(log.capturing);
    log.print("kept");
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {}, true), host, now), 0);
    EXPECT_TRUE(log.capturing);
    EXPECT_EQ(log.ring.size(), 4u) << "a renewal keeps what waits";
    ASSERT_EQ(monitor.configure(monitorRequest(10, 100, {}, false), host, now), 0);
    EXPECT_FALSE(log.capturing);
}

TEST(LogRing, TakesUpToItsCapacityThenCountsAndHoldsTheGap)
{
    sei::LogRing<8> ring;
    for (uint8_t i = 0; i < 8; ++i) {
        EXPECT_TRUE(ring.put(i));
    }
    EXPECT_FALSE(ring.put(8));
    EXPECT_EQ(ring.takeLost(100), 0u) << "not before the bytes ahead of the gap are out";
    uint8_t out[8];
    ASSERT_EQ(ring.peek(out, 3), 3u);
    ring.consume(3);
    EXPECT_FALSE(ring.put(9)) << "after an overflow nothing goes in before the gap is reported";
    ASSERT_EQ(ring.peek(out, 8), 5u);
    EXPECT_EQ(out[0], 3);
    ring.consume(5);
    EXPECT_EQ(ring.takeLost(1), 1u) << "at most what one frame carries";
    EXPECT_FALSE(ring.put(10));
    EXPECT_EQ(ring.takeLost(100), 2u);
    EXPECT_FALSE(ring.pending());
    EXPECT_TRUE(ring.put(11));
    EXPECT_EQ(ring.size(), 1u);
    // Indices wrap far past the capacity.
    for (int i = 0; i < 10000; ++i) {
        ring.consume(1);
        ASSERT_TRUE(ring.put(static_cast<uint8_t>(i)));
    }
    ASSERT_EQ(ring.peek(out, 1), 1u);
    EXPECT_EQ(out[0], static_cast<uint8_t>(9999));
    ring.clear();
    EXPECT_EQ(ring.size(), 0u);
    EXPECT_FALSE(ring.pending());
}

} // namespace
