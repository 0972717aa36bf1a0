// The scan's binary search (hostconfig::SerialSearch) on simulated buses:
// each probe answered as the nodes' own rule answers it
// (sei::SeiServer::probeMatches), with nodes that share long prefixes, the
// extreme serial numbers, a serial number two nodes carry, nodes without
// one, a node that leaves in the middle of the search at every possible
// moment, a probe that fails, and a device that answers everything.
#include <hostconfig/SerialSearch.hpp>

#include <sei/SeiServer.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

namespace {

using hostconfig::SerialSearch;

// The serial numbers on the bus; a probe matches as a node decides.
struct SimulatedBus {
    std::multiset<uint32_t> serials;
    unsigned probes = 0;
    // After this many probes the node `leaving` is gone (no limit: ~0u).
    unsigned leavesAfter = ~0u;
    uint32_t leaving = 0;

    SerialSearch::Answer probe(uint8_t bits, uint32_t value)
    {
        EXPECT_LE(bits, 32u);
        EXPECT_EQ(value & ~sei::seiProbeMask(bits), 0u) << "a probe's value has bits below its mask";
        if (probes++ == leavesAfter) {
            serials.erase(serials.find(leaving));
        }
        for (const uint32_t serial : serials) {
            if (sei::SeiServer::probeMatches(serial, bits, value)) {
                return SerialSearch::Answer::Match;
            }
        }
        return SerialSearch::Answer::Silent;
    }
};

std::vector<uint32_t> search(SimulatedBus& bus, SerialSearch::Outcome expected = SerialSearch::Outcome::Done)
{
    SerialSearch searching([&bus](uint8_t bits, uint32_t value) { return bus.probe(bits, value); });
    EXPECT_EQ(searching.run(), expected);
    EXPECT_EQ(searching.probes(), bus.probes);
    return searching.serials();
}

// What a search must find: every distinct serial number but 0, ascending.
std::vector<uint32_t> expectedOf(const std::multiset<uint32_t>& serials)
{
    std::set<uint32_t> distinct(serials.begin(), serials.end());
    distinct.erase(0);
    return {distinct.begin(), distinct.end()};
}

TEST(SerialSearchTest, AnEmptyBusTakesOneProbe)
{
    SimulatedBus bus;
    EXPECT_TRUE(search(bus).empty());
    EXPECT_EQ(bus.probes, 1u);
}

TEST(SerialSearchTest, OneNodeTakesAProbePerBitAndOneForEachZeroBit)
{
    for (const uint32_t serial : {0x00001267u, 0x12345678u, 0xFFFFFFFEu, 0x80000001u, 1u}) {
        SimulatedBus bus{{serial}};
        EXPECT_EQ(search(bus), std::vector<uint32_t>{serial});
        // The first probe and one per bit (its 0 branch); where the 0 branch
        // answered, the 1 branch may hold another node and is probed too;
        // and an inferred last bit is confirmed.
        const unsigned zeroBits = 32 - static_cast<unsigned>(__builtin_popcount(serial));
        EXPECT_LE(bus.probes, 1 + 32 + zeroBits + 1) << std::hex << serial;
    }
}

TEST(SerialSearchTest, FindsTheExtremeSerialNumbers)
{
    SimulatedBus bus{{1u, 0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu}};
    EXPECT_EQ(search(bus), (std::vector<uint32_t>{1u, 0x7FFFFFFFu, 0x80000000u, 0xFFFFFFFFu}));
}

TEST(SerialSearchTest, TheLargestSerialNumberAloneIsFoundByInferenceAndConfirmed)
{
    // Every 0 branch on its way is silent, so every bit is inferred; the
    // whole serial number is probed before it counts.
    SimulatedBus bus{{0xFFFFFFFFu}};
    EXPECT_EQ(search(bus), std::vector<uint32_t>{0xFFFFFFFFu});
    EXPECT_EQ(bus.probes, 34u);
}

TEST(SerialSearchTest, SerialNumberZeroNeverAnswers)
{
    SimulatedBus bus{{0u, 0u}};
    EXPECT_TRUE(search(bus).empty());
    SimulatedBus mixed{{0u, 1u, 0u}};
    EXPECT_EQ(search(mixed), std::vector<uint32_t>{1u});
}

TEST(SerialSearchTest, NodesSharingLongPrefixesAreToldApart)
{
    SimulatedBus bus{{0x12345678u, 0x12345679u, 0x1234567Au, 0x12340000u, 0x92345678u}};
    EXPECT_EQ(search(bus), expectedOf(bus.serials));
}

TEST(SerialSearchTest, ASerialNumberTwoNodesCarryIsFoundOnce)
{
    SimulatedBus bus{{4711u, 4711u, 4712u}};
    EXPECT_EQ(search(bus), (std::vector<uint32_t>{4711u, 4712u}));
}

TEST(SerialSearchTest, RandomBusesAreFoundExactly)
{
    std::mt19937 random(20240611);
    for (int trial = 0; trial < 200; ++trial) {
        SimulatedBus bus;
        const int nodes = 1 + static_cast<int>(random() % 40);
        // Serial numbers in a few narrow families, as a production run
        // numbers its boards, and some anywhere.
        const uint32_t family = random();
        for (int i = 0; i < nodes; ++i) {
            const uint32_t serial = i % 3 == 0 ? static_cast<uint32_t>(random()) : family + (random() % 64);
            bus.serials.insert(serial);
        }
        const std::vector<uint32_t> expected = expectedOf(bus.serials);
        EXPECT_EQ(search(bus), expected) << "trial " << trial;
        // Bounded by two probes per bit for each node.
        EXPECT_LE(bus.probes, 1 + 65 * expected.size()) << "trial " << trial;
    }
}

TEST(SerialSearchTest, ANodeLeavingAtAnyMomentLeavesNoSerialNumberNobodyHas)
{
    const std::multiset<uint32_t> start{0x00000001u, 0x40000000u, 0x40000001u, 0xC0FFEE00u, 0xFFFFFFFFu};
    for (const uint32_t leaving : start) {
        SimulatedBus whole{start};
        search(whole);
        for (unsigned after = 0; after <= whole.probes; ++after) {
            SimulatedBus bus{start};
            bus.leaving = leaving;
            bus.leavesAfter = after;
            const std::vector<uint32_t> found = search(bus);
            EXPECT_TRUE(std::is_sorted(found.begin(), found.end()));
            for (const uint32_t serial : start) {
                const bool present = std::find(found.begin(), found.end(), serial) != found.end();
                // Every node that stayed is found; the one that left may or
                // may not be, by when it left.
                if (serial != leaving) {
                    EXPECT_TRUE(present) << std::hex << serial << " missing, " << leaving << " left after " << after;
                }
            }
            for (const uint32_t serial : found) {
                EXPECT_EQ(start.count(serial), 1u) << std::hex << serial << " found, which no node has";
            }
        }
    }
}

TEST(SerialSearchTest, AFailedProbeEndsTheSearch)
{
    SimulatedBus bus{{0x10u, 0x80000000u}};
    unsigned probes = 0;
    SerialSearch searching([&](uint8_t bits, uint32_t value) {
        return ++probes == 40 ? SerialSearch::Answer::Failed : bus.probe(bits, value);
    });
    EXPECT_EQ(searching.run(), SerialSearch::Outcome::Failed);
    EXPECT_EQ(searching.probes(), 40u);
    EXPECT_EQ(searching.serials(), std::vector<uint32_t>{0x10u});
}

TEST(SerialSearchTest, SomethingAnsweringEveryProbeStopsTheSearch)
{
    unsigned probes = 0;
    SerialSearch searching(
        [&](uint8_t, uint32_t) {
            ++probes;
            return SerialSearch::Answer::Match;
        },
        8);
    EXPECT_EQ(searching.run(), SerialSearch::Outcome::TooMany);
    EXPECT_EQ(searching.serials().size(), 9u);
    EXPECT_LT(probes, 100u);
}

TEST(SerialSearchTest, RunsAgainFromTheStart)
{
    SimulatedBus bus{{5u, 6u}};
    SerialSearch searching([&bus](uint8_t bits, uint32_t value) { return bus.probe(bits, value); });
    EXPECT_EQ(searching.run(), SerialSearch::Outcome::Done);
    bus.serials.insert(7u);
    EXPECT_EQ(searching.run(), SerialSearch::Outcome::Done);
    EXPECT_EQ(searching.serials(), (std::vector<uint32_t>{5u, 6u, 7u}));
}

} // namespace
