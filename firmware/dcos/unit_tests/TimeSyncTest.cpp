// Host tests of the global time base (docs/protocols/time.md): the byte
// layout of Sync, FollowUp and Probe written out by hand from the
// specification, every refusal of the decoder, the FollowUp's 56 bits made
// whole again, and ClockServo's decisions: pairing, master preference and
// hand-over, the confirmation of a large step, and a simulated network of
// drifting clocks whose synchronised error must stay within drift x
// interval while the free-running one does not.
#include <dcos/internal/ClockServo.hpp>
#include <dcos/internal/TimeSyncMessage.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace {

using namespace dcos::internal;
using dcos::GlobalTimeStatus;
using dcos::TimeProbe;
using dcos::TimeRole;

constexpr uint64_t kSecond = 1'000'000'000;
constexpr uint64_t kMs = 1'000'000;

using Frame = std::array<uint8_t, kTimeSyncBytes>;

Frame sync(uint8_t sequence, uint64_t seconds, uint8_t rank = 0, uint32_t intervalMs = 1000)
{
    uint8_t bytes[kTimeSyncBytes];
    encodeTimeSync(sequence, seconds, rank, intervalMs, bytes);
    Frame out;
    std::copy(std::begin(bytes), std::end(bytes), out.begin());
    return out;
}

Frame followUp(uint8_t sequence, uint64_t timeOfDay)
{
    uint8_t bytes[kTimeSyncBytes];
    encodeTimeFollowUp(sequence, timeOfDay, bytes);
    Frame out;
    std::copy(std::begin(bytes), std::end(bytes), out.begin());
    return out;
}

TimeSyncFrame decoded(const Frame& frame)
{
    TimeSyncFrame out;
    EXPECT_EQ(decodeTimeSync(frame.data(), frame.size(), out), TimeSyncError::None);
    return out;
}

TEST(TimeSyncMessage, TheSyncLayoutIsTheSpecifications)
{
    // Sequence 5, 0x12_3456_789A seconds, rank 3, 2.5 s.
    EXPECT_EQ(sync(5, 0x123456789Aull, 3, 2500), (Frame{0x05, 0x12, 0x34, 0x56, 0x78, 0x9A, 0x03, 25}));
    const TimeSyncFrame frame = decoded(sync(63, 1'764'000'000, 15, 100));
    EXPECT_EQ(frame.kind, TimeSyncKind::Sync);
    EXPECT_EQ(frame.sequence, 63);
    EXPECT_EQ(frame.seconds, 1'764'000'000u);
    EXPECT_EQ(frame.rank, 15);
    EXPECT_EQ(frame.intervalMs, 100u);
}

TEST(TimeSyncMessage, TheFollowUpLayoutIsTheSpecifications)
{
    EXPECT_EQ(followUp(1, 0xAB11223344556677ull), (Frame{0x41, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77}))
        << "the top eight bits are not sent";
    const TimeSyncFrame frame = decoded(followUp(62, 0x00FFEEDDCCBBAA99ull));
    EXPECT_EQ(frame.kind, TimeSyncKind::FollowUp);
    EXPECT_EQ(frame.sequence, 62);
    EXPECT_EQ(frame.nanosecondsLow, 0x00FFEEDDCCBBAA99ull);
    uint8_t probe[kTimeProbeBytes];
    encodeTimeProbe(9, probe);
    EXPECT_EQ(probe[0], 0x89);
}

TEST(TimeSyncMessage, EveryMalformedFrameIsRefusedWithItsReason)
{
    TimeSyncFrame out;
    const Frame good = sync(1, 1000);
    EXPECT_EQ(decodeTimeSync(good.data(), 0, out), TimeSyncError::WrongLength);
    EXPECT_EQ(decodeTimeSync(good.data(), 7, out), TimeSyncError::WrongLength);
    const Frame follow = followUp(1, 5);
    EXPECT_EQ(decodeTimeSync(follow.data(), 6, out), TimeSyncError::WrongLength);
    const uint8_t longProbe[2] = {0x80, 0};
    EXPECT_EQ(decodeTimeSync(longProbe, 2, out), TimeSyncError::WrongLength);
    const uint8_t kindThree[8] = {0xC0};
    EXPECT_EQ(decodeTimeSync(kindThree, 8, out), TimeSyncError::UnknownKind);
    Frame badRank = good;
    badRank[6] = 0x10;
    EXPECT_EQ(decodeTimeSync(badRank.data(), 8, out), TimeSyncError::BadRank);
    Frame noInterval = good;
    noInterval[7] = 0;
    EXPECT_EQ(decodeTimeSync(noInterval.data(), 8, out), TimeSyncError::BadInterval);
}

TEST(TimeSyncMessage, TheFollowUpsTimeIsMadeWholeFromItsSyncsSeconds)
{
    const uint64_t seconds = 1'764'547'200; // 2025-12-01.
    for (const uint64_t extra : std::array<uint64_t, 5>{0, 1, 999'999'999, 1'500'000'000, 1'999'999'999}) {
        const uint64_t time = seconds * kSecond + extra;
        const TimeSyncFrame frame = decoded(followUp(0, time));
        uint64_t whole = 0;
        ASSERT_TRUE(timeOfDayOfFollowUp(seconds, frame.nanosecondsLow, whole)) << extra;
        EXPECT_EQ(whole, time);
    }
    // A time across a 2^56 boundary from its seconds.
    const uint64_t boundary = uint64_t{1} << 60;
    const uint64_t justBefore = (boundary - 300 * kMs) / kSecond;
    const uint64_t time = boundary + 200 * kMs;
    uint64_t whole = 0;
    ASSERT_TRUE(timeOfDayOfFollowUp(justBefore, decoded(followUp(0, time)).nanosecondsLow, whole));
    EXPECT_EQ(whole, time);
    // Before its Sync's second, or two seconds after: not that Sync's.
    EXPECT_FALSE(timeOfDayOfFollowUp(seconds, decoded(followUp(0, seconds * kSecond - 1)).nanosecondsLow, whole));
    EXPECT_FALSE(timeOfDayOfFollowUp(seconds, decoded(followUp(0, (seconds + 2) * kSecond)).nanosecondsLow, whole));
    EXPECT_FALSE(timeOfDayOfFollowUp(uint64_t{1} << 40, 0, whole)) << "seconds past 40 bits";
}

// ---- the servo ------------------------------------------------------------

struct Servo {
    ClockServo servo;
    // This node's clock: time of day = base + uptime.
    uint64_t base = 0;

    explicit Servo(uint16_t node, TimeRole role = TimeRole::Follower, uint8_t rank = 0) : servo(node)
    {
        servo.configure(role, rank, 1000);
    }

    void onSync(uint8_t interface, uint16_t node, uint8_t sequence, uint64_t seconds, uint64_t at, uint8_t rank = 0)
    {
        servo.onSync(interface, node, decoded(sync(sequence, seconds, rank)), at);
    }

    bool onFollowUp(uint8_t interface, uint16_t node, uint8_t sequence, uint64_t masterTime, uint64_t at)
    {
        const ClockCorrection correction =
            servo.onFollowUp(interface, node, decoded(followUp(sequence, masterTime)), at,
                             [this](uint64_t uptime) { return base + uptime; });
        if (correction.apply) {
            base = correction.timeOfDayNs - correction.atUptimeNs;
        }
        return correction.apply;
    }

    GlobalTimeStatus status(uint64_t now) const { return servo.status(now); }
};

constexpr uint64_t kEpoch = 1'764'547'200ull * kSecond;

TEST(ClockServo, AFollowUpPairsOnlyWithItsOwnSync)
{
    Servo node(2);
    node.onSync(0, 1, 7, kEpoch / kSecond, 10 * kMs);
    EXPECT_FALSE(node.onFollowUp(0, 1, 8, kEpoch, 11 * kMs)) << "another sequence number";
    EXPECT_FALSE(node.onFollowUp(1, 1, 7, kEpoch, 11 * kMs)) << "another interface";
    EXPECT_FALSE(node.onFollowUp(0, 3, 7, kEpoch, 11 * kMs)) << "another node";
    EXPECT_TRUE(node.onFollowUp(0, 1, 7, kEpoch, 11 * kMs));
    EXPECT_EQ(node.base + 10 * kMs, kEpoch) << "the time at the Sync's interrupt becomes the master's";
    EXPECT_FALSE(node.onFollowUp(0, 1, 7, kEpoch, 12 * kMs)) << "a Sync pairs once";
    // A FollowUp more than two intervals after its Sync is too late.
    node.onSync(0, 1, 8, kEpoch / kSecond + 1, 1010 * kMs);
    EXPECT_FALSE(node.onFollowUp(0, 1, 8, kEpoch + kSecond, 3011 * kMs));
    const GlobalTimeStatus status = node.status(3011 * kMs);
    EXPECT_EQ(status.unpaired, 5u);
    EXPECT_EQ(status.corrections, 1u);
}

TEST(ClockServo, ANodeWithItsRoleOffNeverCorrects)
{
    Servo node(2, TimeRole::Off);
    node.onSync(0, 1, 0, kEpoch / kSecond, 10 * kMs);
    EXPECT_FALSE(node.onFollowUp(0, 1, 0, kEpoch, 11 * kMs));
    EXPECT_EQ(node.base, 0u);
}

TEST(ClockServo, AFollowerTakesTheMostPreferredMasterAndAnotherWhenItFallsSilent)
{
    Servo node(5);
    node.onSync(0, 3, 0, kEpoch / kSecond, 0, 2);
    EXPECT_EQ(node.status(0).masterNode, 3);
    node.onSync(0, 4, 0, kEpoch / kSecond, kMs, 1);
    EXPECT_EQ(node.status(kMs).masterNode, 4) << "rank 1 over rank 2";
    node.onSync(0, 3, 1, kEpoch / kSecond, 2 * kMs, 2);
    EXPECT_EQ(node.status(2 * kMs).masterNode, 4);
    EXPECT_EQ(node.status(2 * kMs).ignored, 1u);
    node.onSync(0, 2, 1, kEpoch / kSecond, 3 * kMs, 1);
    EXPECT_EQ(node.status(3 * kMs).masterNode, 2) << "equal ranks: the lower node";
    // Node 2 falls silent for three of its intervals: node 3 is taken.
    node.onSync(0, 3, 2, kEpoch / kSecond, 2000 * kMs, 2);
    EXPECT_EQ(node.status(2000 * kMs).masterNode, 2);
    node.onSync(0, 3, 3, kEpoch / kSecond, 3004 * kMs, 2);
    EXPECT_EQ(node.status(3004 * kMs).masterNode, 3);
}

TEST(ClockServo, AMasterStaysQuietWhileAMorePreferredOneIsHeardAndTakesOverAfter)
{
    Servo backup(2, TimeRole::Master, 1);
    EXPECT_TRUE(backup.servo.sending(0));
    backup.onSync(0, 7, 0, kEpoch / kSecond, 10 * kMs, 3);
    EXPECT_TRUE(backup.servo.sending(10 * kMs)) << "a less preferred master is ignored";
    EXPECT_EQ(backup.status(10 * kMs).ignored, 1u);
    backup.onSync(0, 9, 0, kEpoch / kSecond, 20 * kMs, 0);
    EXPECT_FALSE(backup.servo.sending(20 * kMs));
    EXPECT_TRUE(backup.onFollowUp(0, 9, 0, kEpoch, 21 * kMs)) << "and it follows the better one";
    EXPECT_FALSE(backup.servo.sending(3020 * kMs));
    EXPECT_TRUE(backup.servo.sending(3021 * kMs)) << "three silent intervals later it sends";
    EXPECT_EQ(backup.status(3021 * kMs).masterNode, 2);
}

TEST(ClockServo, ALargeStepOnceInStepWaitsForTheNextSyncToConfirmIt)
{
    Servo node(2);
    uint64_t uptime = 5 * kSecond;
    uint64_t master = kEpoch;
    uint8_t sequence = 0;
    const auto round = [&](int64_t masterJump) {
        master += kSecond + static_cast<uint64_t>(masterJump);
        uptime += kSecond;
        node.onSync(0, 1, sequence, master / kSecond, uptime);
        return node.onFollowUp(0, 1, sequence++, master, uptime + kMs);
    };
    ASSERT_TRUE(round(0));
    ASSERT_TRUE(round(0));
    ASSERT_TRUE(round(0));
    EXPECT_TRUE(node.status(uptime).inStep);
    // One sync 50 ms off: held, the clock keeps its time.
    master += 50 * kMs;
    const uint64_t before = node.base;
    EXPECT_FALSE(round(0));
    EXPECT_EQ(node.base, before);
    EXPECT_EQ(node.status(uptime).held, 1u);
    // The next says the same: the master's clock really moved. Applied.
    EXPECT_TRUE(round(0));
    EXPECT_EQ(node.base + uptime, master);
    // A single bad one after that is held and then dropped when the next
    // sync is normal again.
    master += 30 * kMs;
    EXPECT_FALSE(round(0));
    master -= 30 * kMs;
    EXPECT_TRUE(round(0));
    EXPECT_EQ(node.base + uptime, master);
    EXPECT_EQ(node.status(uptime).held, 2u);
    EXPECT_EQ(node.status(uptime).largestOffsetNs, 0u) << "a held step is not a measured offset";
}

// A node 250 ppm fast whose interrupt timestamp of one Sync is a tick of
// 10 ms short: the correction it would give strays from the drift's
// prediction, is held, and the next sync puts the clock right with the
// usual offset. Nothing of the bad one reaches the clock or the bound.
TEST(ClockServo, ABadTimestampStrayingFromTheDriftsPredictionIsHeldAndDropped)
{
    Servo node(2);
    uint64_t master = kEpoch;
    uint64_t trueTime = 5 * kSecond;
    uint8_t sequence = 0;
    const auto uptime = [](uint64_t t) { return t + t / 4000; }; // 250 ppm fast.
    const auto round = [&](int64_t stampError) {
        master += kSecond;
        trueTime += kSecond;
        const uint64_t at = uptime(trueTime) + static_cast<uint64_t>(stampError);
        node.onSync(0, 1, sequence, master / kSecond, at);
        return node.onFollowUp(0, 1, sequence++, master, at + kMs);
    };
    for (int i = 0; i < 5; ++i) {
        ASSERT_TRUE(round(0));
    }
    const int64_t usual = node.status(0).lastOffsetNs;
    EXPECT_NEAR(static_cast<double>(usual), -250'000.0, 100.0);
    EXPECT_NEAR(node.status(0).driftPpb, 250'000, 100);
    const uint64_t before = node.base;
    EXPECT_FALSE(round(-10 * static_cast<int64_t>(kMs)));
    EXPECT_EQ(node.base, before);
    EXPECT_EQ(node.status(0).held, 1u);
    EXPECT_TRUE(round(0));
    EXPECT_NEAR(static_cast<double>(node.status(0).lastOffsetNs), 2.0 * static_cast<double>(usual), 200.0)
        << "two intervals of drift, as predicted";
    EXPECT_TRUE(round(0));
    EXPECT_LE(node.status(0).largestOffsetNs, 500'200u) << "the held correction is no part of the bound";
    EXPECT_NEAR(node.status(0).driftPpb, 250'000, 100);
}

TEST(ClockServo, ProbesAreKeptNewestLast)
{
    Servo node(2);
    for (uint8_t i = 0; i < 11; ++i) {
        node.servo.onProbe(TimeProbe{0, i, 9, kEpoch + i});
    }
    TimeProbe probes[dcos::GlobalTime::kProbes];
    ASSERT_EQ(node.servo.probes(probes, dcos::GlobalTime::kProbes), dcos::GlobalTime::kProbes);
    EXPECT_EQ(probes[0].sequence, 3);
    EXPECT_EQ(probes[7].sequence, 10);
    EXPECT_EQ(node.servo.probes(probes, 2), 2u);
    EXPECT_EQ(probes[1].sequence, 10);
    EXPECT_EQ(node.status(0).probes, 11u);
}

// A master and two nodes on one bus, each with a crystal off by a few
// hundred ppm, for ten minutes of syncs once a second, some lost. The
// difference of any node's clock from the master's, sampled at random
// moments, stays within drift x interval plus the timestamps' error; a
// node that does not follow drifts far outside it.
TEST(ClockServo, SimulatedNodesStayWithinDriftTimesTheIntervalOfTheMaster)
{
    struct Node {
        double ppm;          // Crystal error: +fast.
        double startUptime;  // Seconds of true time at which its uptime was 0.
        uint64_t base;       // Its clock's base; time of day = base + uptime.
        ClockServo servo;
        TimeRole role;
    };
    std::vector<Node> nodes = {
        {0.0, 0.0, kEpoch, ClockServo(1), TimeRole::Master},
        {-250.0, 0.7, kEpoch - 3 * kSecond, ClockServo(2), TimeRole::Follower},
        {+168.0, 1.3, kEpoch + 12 * kSecond, ClockServo(3), TimeRole::Follower},
        {+300.0, 0.2, kEpoch, ClockServo(4), TimeRole::Off},
    };
    for (Node& node : nodes) {
        node.servo.configure(node.role, 0, 1000);
    }
    std::mt19937 random(14);
    std::uniform_real_distribution<double> jitter(0.0, 20e-6); // Interrupt latency, up to 20 us.
    const auto uptimeOf = [](const Node& node, double trueTime) {
        return static_cast<uint64_t>((trueTime - node.startUptime) * (1.0 + node.ppm * 1e-6) * 1e9);
    };
    const auto timeOfDay = [&](const Node& node, double trueTime) { return node.base + uptimeOf(node, trueTime); };
    double worst = 0.0;
    double worstFree = 0.0;
    const double bound = (250.0 + 1.0) * 1e-6 * 2 + 40e-6; // A lost sync doubles the interval.
    uint8_t sequence = 0;
    for (int second = 2; second < 600; ++second) {
        const double end = second + 0.001; // The Sync frame's end on the bus.
        const bool lost = second % 20 == 7; // Never two in a row: the bound below allows one.
        Node& master = nodes[0];
        const uint64_t masterTime = timeOfDay(master, end + jitter(random));
        for (size_t i = 1; i < nodes.size(); ++i) {
            Node& node = nodes[i];
            if (lost && i == 1) {
                continue; // Node 2 misses this Sync.
            }
            const uint64_t at = uptimeOf(node, end + jitter(random));
            node.servo.onSync(0, 1, decoded(sync(sequence, masterTime / kSecond)), at);
            const ClockCorrection correction =
                node.servo.onFollowUp(0, 1, decoded(followUp(sequence, masterTime)), at + 500'000,
                                      [&node](uint64_t uptime) { return node.base + uptime; });
            if (correction.apply) {
                node.base = correction.timeOfDayNs - correction.atUptimeNs;
            }
        }
        ++sequence;
        sequence &= kTimeSyncSequenceMask;
        // A probe at a random moment before the next sync.
        const double probe = second + 0.01 + 0.98 * std::uniform_real_distribution<double>(0, 1)(random);
        const double reference = static_cast<double>(timeOfDay(master, probe));
        if (second > 4) {
            for (size_t i = 1; i < 3; ++i) {
                worst = std::max(worst, std::abs(static_cast<double>(timeOfDay(nodes[i], probe)) - reference) / 1e9);
            }
            worstFree = std::max(worstFree, std::abs(static_cast<double>(timeOfDay(nodes[3], probe)) - reference) / 1e9);
        }
    }
    EXPECT_LT(worst, bound);
    EXPECT_GT(worst, 150e-6) << "the drift is really there between syncs";
    EXPECT_GT(worstFree, 0.15) << "300 ppm over ten minutes, unsynchronised";
    for (size_t i = 1; i < 3; ++i) {
        const GlobalTimeStatus status = nodes[i].servo.status(uptimeOf(nodes[i], 600));
        EXPECT_TRUE(status.inStep) << i;
        EXPECT_LT(static_cast<double>(status.largestOffsetNs) / 1e9, bound) << i;
        // The drift estimate, in ppb: node 2 is 250 ppm slow, node 3 168 fast.
        const double expected = nodes[i].ppm * 1000.0;
        EXPECT_NEAR(status.driftPpb, expected, 40'000.0) << i;
    }
    EXPECT_EQ(nodes[3].servo.status(0).corrections, 0u);
}

} // namespace
