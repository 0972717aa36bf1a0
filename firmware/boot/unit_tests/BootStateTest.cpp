#include <boot/BootPlanner.hpp>
#include <boot/BootState.hpp>
#include <boot/Crc32.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include <string>

namespace {

using boot::BootPlan;
using boot::BootPlanner;
using boot::BootState;
using boot::TrialState;

struct Sector {
    uint8_t bytes[BootState::kSize];
};

Sector encoded(const BootState& state)
{
    Sector sector;
    state.encode(sector.bytes);
    return sector;
}

BootState state(uint32_t sequence, uint8_t confirmed, uint8_t trialSlot = BootState::kNoSlot,
                TrialState trial = TrialState::None)
{
    BootState s;
    s.sequence = sequence;
    s.confirmedSlot = confirmed;
    s.trialSlot = trialSlot;
    s.trial = trial;
    return s;
}

TEST(Crc32Test, MatchesTheCheckValueOfIeee8023)
{
    EXPECT_EQ(boot::crc32("123456789", 9), 0xCBF43926u);
    EXPECT_EQ(boot::crc32("", 0), 0u);
}

TEST(BootStateTest, RoundTripsAndRefusesEveryChangedByte)
{
    BootState original = state(41, 1, 0, TrialState::Booting);
    original.reverts = 3;
    const Sector sector = encoded(original);
    BootState decoded;
    ASSERT_TRUE(BootState::decode(sector.bytes, decoded));
    EXPECT_EQ(decoded.sequence, 41u);
    EXPECT_EQ(decoded.confirmedSlot, 1);
    EXPECT_EQ(decoded.trialSlot, 0);
    EXPECT_EQ(decoded.trial, TrialState::Booting);
    EXPECT_EQ(decoded.reverts, 3u);
    for (size_t at = 0; at < BootState::kSize; ++at) {
        Sector changed = sector;
        changed.bytes[at] ^= 0x01;
        BootState ignored;
        EXPECT_FALSE(BootState::decode(changed.bytes, ignored)) << "byte " << at;
    }
}

TEST(BootStateTest, RefusesInconsistentRecordsEvenWithARightCrc)
{
    for (const BootState& bad : {state(1, 2), state(1, 0, 0, TrialState::Pending), state(1, 0, 1, TrialState::None),
                                 state(1, 0, BootState::kNoSlot, TrialState::Booting)}) {
        BootState ignored;
        EXPECT_FALSE(BootState::decode(encoded(bad).bytes, ignored));
    }
    Sector trial = encoded(state(1, 0));
    trial.bytes[15] = 3;
    const uint32_t crc = boot::crc32(trial.bytes, 508);
    std::memcpy(trial.bytes + 508, &crc, 4);
    BootState ignored;
    EXPECT_FALSE(BootState::decode(trial.bytes, ignored)) << "trial state 3";
}

TEST(BootStateTest, TheNewerValidCopyCounts)
{
    BootState out;
    unsigned copy = 9;
    const Sector older = encoded(state(7, 0));
    const Sector newer = encoded(state(8, 1));
    ASSERT_TRUE(BootState::newest(older.bytes, newer.bytes, out, copy));
    EXPECT_EQ(copy, 1u);
    EXPECT_EQ(out.confirmedSlot, 1);
    ASSERT_TRUE(BootState::newest(newer.bytes, older.bytes, out, copy));
    EXPECT_EQ(copy, 0u);
    Sector torn = newer;
    torn.bytes[300] = 0xAA;
    ASSERT_TRUE(BootState::newest(older.bytes, torn.bytes, out, copy)) << "a torn newer copy: the older stands";
    EXPECT_EQ(copy, 0u);
    EXPECT_EQ(out.sequence, 7u);
    const Sector wrapped = encoded(state(0, 1));
    const Sector last = encoded(state(0xFFFFFFFF, 0));
    ASSERT_TRUE(BootState::newest(last.bytes, wrapped.bytes, out, copy));
    EXPECT_EQ(copy, 1u) << "sequence 0 follows 0xFFFFFFFF";
    Sector blank{};
    EXPECT_FALSE(BootState::newest(blank.bytes, blank.bytes, out, copy));
}

// The planner against slots whose validity the test sets, counting the
// verifications it asks for.
struct Slots {
    bool valid[2] = {true, true};
    int asked[2] = {0, 0};

    BootPlan plan(const BootState* stored)
    {
        return BootPlanner::plan(stored, [this](uint8_t slot) {
            ++asked[slot];
            return valid[slot];
        });
    }
};

TEST(BootPlannerTest, AnImageNothingConfirmedBootsOnlyAsATrial)
{
    Slots slots;
    BootPlan plan = slots.plan(nullptr);
    EXPECT_EQ(plan.action, BootPlan::Action::Boot);
    EXPECT_EQ(plan.slot, 0);
    EXPECT_TRUE(plan.trial);
    EXPECT_TRUE(plan.write);
    EXPECT_EQ(plan.state.confirmedSlot, BootState::kNoSlot);
    EXPECT_EQ(plan.state.trial, TrialState::Booting);
    EXPECT_EQ(plan.state.trialSlot, 0);
    slots.valid[0] = false;
    plan = slots.plan(nullptr);
    EXPECT_EQ(plan.slot, 1);
    EXPECT_TRUE(plan.trial);
    // It never confirmed: dropped, and with nothing else valid, recovery.
    const BootState after = plan.state;
    plan = slots.plan(&after);
    EXPECT_EQ(plan.action, BootPlan::Action::Recovery);
    EXPECT_TRUE(plan.reverted);
}

TEST(BootPlannerTest, TheConfirmedImageBootsWithoutAWriteOrALookAtTheOtherSlot)
{
    Slots slots;
    const BootState stored = state(5, 1);
    const BootPlan plan = slots.plan(&stored);
    EXPECT_EQ(plan.action, BootPlan::Action::Boot);
    EXPECT_EQ(plan.slot, 1);
    EXPECT_FALSE(plan.write);
    EXPECT_EQ(slots.asked[0], 0);
    EXPECT_EQ(slots.asked[1], 1);
}

TEST(BootPlannerTest, APendingTrialBootsOnceAsATrial)
{
    Slots slots;
    const BootState stored = state(5, 0, 1, TrialState::Pending);
    const BootPlan plan = slots.plan(&stored);
    EXPECT_EQ(plan.slot, 1);
    EXPECT_TRUE(plan.trial);
    EXPECT_TRUE(plan.write);
    EXPECT_EQ(plan.state.trial, TrialState::Booting);
    EXPECT_EQ(plan.state.confirmedSlot, 0) << "the old image stays confirmed until the new one confirms";
}

TEST(BootPlannerTest, ATrialThatNeverConfirmedIsRevertedOnTheNextBoot)
{
    Slots slots;
    BootState stored = state(6, 0, 1, TrialState::Booting);
    stored.reverts = 2;
    const BootPlan plan = slots.plan(&stored);
    EXPECT_EQ(plan.slot, 0);
    EXPECT_FALSE(plan.trial);
    EXPECT_TRUE(plan.reverted);
    EXPECT_TRUE(plan.write);
    EXPECT_EQ(plan.state.trial, TrialState::None);
    EXPECT_EQ(plan.state.trialSlot, BootState::kNoSlot);
    EXPECT_EQ(plan.state.reverts, 3u);
    EXPECT_EQ(slots.asked[1], 0) << "the reverted image is not even verified";
}

TEST(BootPlannerTest, AnInvalidPendingImageIsDroppedAndTheConfirmedOneBoots)
{
    Slots slots;
    slots.valid[1] = false;
    const BootState stored = state(6, 0, 1, TrialState::Pending);
    const BootPlan plan = slots.plan(&stored);
    EXPECT_EQ(plan.slot, 0);
    EXPECT_FALSE(plan.trial);
    EXPECT_TRUE(plan.reverted);
    EXPECT_EQ(plan.state.trial, TrialState::None);
}

TEST(BootPlannerTest, ADecayedConfirmedImageFallsBackToTheOtherSlot)
{
    Slots slots;
    slots.valid[0] = false;
    const BootState stored = state(6, 0);
    const BootPlan plan = slots.plan(&stored);
    EXPECT_EQ(plan.slot, 1);
    EXPECT_EQ(plan.state.confirmedSlot, 1);
    EXPECT_TRUE(plan.write);
}

TEST(BootPlannerTest, ARevertedTrialIsNeverTheFallback)
{
    Slots slots;
    slots.valid[0] = false;
    const BootState stored = state(6, 0, 1, TrialState::Booting);
    const BootPlan plan = slots.plan(&stored);
    EXPECT_EQ(plan.action, BootPlan::Action::Recovery);
    EXPECT_TRUE(plan.write) << "the revert is still recorded";
    EXPECT_EQ(plan.state.trial, TrialState::None);
}

TEST(BootPlannerTest, NoValidImageIsRecovery)
{
    Slots slots;
    slots.valid[0] = slots.valid[1] = false;
    EXPECT_EQ(slots.plan(nullptr).action, BootPlan::Action::Recovery);
    const BootState stored = state(2, 1);
    EXPECT_EQ(slots.plan(&stored).action, BootPlan::Action::Recovery);
}

TEST(BootPlannerTest, EveryStateAndValidityEndsInAConsistentPlan)
{
    // Exhaustively: every decodable state, every validity of the two slots.
    std::set<std::string> reasons;
    for (uint8_t confirmed : {uint8_t{0}, uint8_t{1}, BootState::kNoSlot}) {
        for (uint8_t trialSlot : {uint8_t{0}, uint8_t{1}, BootState::kNoSlot}) {
            for (TrialState trial : {TrialState::None, TrialState::Pending, TrialState::Booting}) {
                BootState stored = state(9, confirmed, trialSlot, trial);
                BootState decoded;
                if (!BootState::decode(encoded(stored).bytes, decoded)) {
                    continue;
                }
                for (int validity = 0; validity < 4; ++validity) {
                    Slots slots;
                    slots.valid[0] = (validity & 1) != 0;
                    slots.valid[1] = (validity & 2) != 0;
                    const BootPlan plan = slots.plan(&decoded);
                    reasons.insert(plan.reason);
                    EXPECT_LE(slots.asked[0], 1);
                    EXPECT_LE(slots.asked[1], 1);
                    BootState written;
                    ASSERT_TRUE(BootState::decode(encoded(plan.state).bytes, written)) << "the new state is valid";
                    if (plan.action == BootPlan::Action::Boot) {
                        EXPECT_TRUE(slots.valid[plan.slot]) << "only a valid image boots";
                        EXPECT_EQ(plan.trial, plan.state.trial == TrialState::Booting);
                        if (!plan.trial) {
                            EXPECT_EQ(plan.slot, plan.state.confirmedSlot);
                        }
                    } else {
                        EXPECT_FALSE(plan.trial);
                    }
                    EXPECT_NE(plan.state.trial, TrialState::Pending) << "a boot never leaves a trial pending";
                }
            }
        }
    }
    EXPECT_GE(reasons.size(), 6u);
}

} // namespace
