#include <boot/AtaSectorStore.hpp>
#include <boot/BootControl.hpp>

#include "../../../drivers/ata/unit_tests/FakeAtaDisk.hpp"

#include <ata/AtaRegisters.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace {

using boot::BootControl;
using boot::BootState;
using boot::ConfirmOutcome;
using boot::RunningImage;
using boot::TrialState;

class BootControlTest : public ::testing::Test {
protected:
    void SetUp() override { port_io_mock::reset(); }
    void TearDown() override { port_io_mock::reset(); }

    static ata::AtaPioDisk disk()
    {
        return ata::AtaPioDisk(
            arch_x86::IoWindow::ports(ata::reg::kPrimaryCommandBase, ata::reg::kCommandWindowSize),
            arch_x86::IoWindow::ports(ata::reg::kPrimaryControlBase, ata::reg::kControlWindowSize), 1000);
    }

    static void putState(ata_test::FakeAtaDisk& card, unsigned copy, uint32_t sequence, uint8_t confirmed,
                         uint8_t trialSlot, TrialState trial)
    {
        BootState state;
        state.sequence = sequence;
        state.confirmedSlot = confirmed;
        state.trialSlot = trialSlot;
        state.trial = trial;
        uint8_t record[512];
        state.encode(record);
        card.setSector(boot::card::kBootStateLba + copy, std::vector<uint8_t>(record, record + 512));
    }

    static bool stoppedWatchdog(const std::vector<port_io_mock::Access>& log)
    {
        return std::any_of(log.begin(), log.end(), [](const port_io_mock::Access& access) {
            return access.write && access.port == 0x441;
        });
    }
};

TEST_F(BootControlTest, ReadsTheRunningImageFromTheCommandLine)
{
    const RunningImage trial = RunningImage::fromCommandLine("node=3 boot.slot=B boot.version=1.1.0+4 boot.trial=1");
    EXPECT_TRUE(trial.fromCard);
    EXPECT_EQ(trial.slot, 1);
    EXPECT_TRUE(trial.trial);
    EXPECT_FALSE(trial.reverted);
    EXPECT_STREQ(trial.version, "1.1.0+4");
    const RunningImage reverted = RunningImage::fromCommandLine("boot.slot=A boot.version=1.0.0 boot.reverted=1");
    EXPECT_EQ(reverted.slot, 0);
    EXPECT_TRUE(reverted.reverted);
    EXPECT_FALSE(reverted.trial);
    for (const char* line : {"", "node=3", "boot.slot=C", "boot.slot=AB", "xboot.slot=A"}) {
        EXPECT_FALSE(RunningImage::fromCommandLine(line).fromCard) << line;
    }
    EXPECT_FALSE(RunningImage::fromCommandLine(nullptr).fromCard);
}

TEST_F(BootControlTest, ConfirmingTheTrialWritesTheOlderCopyThenStopsTheWatchdog)
{
    ata_test::FakeAtaDisk card(16384);
    putState(card, 0, 7, 0, BootState::kNoSlot, TrialState::None);
    putState(card, 1, 8, 0, 1, TrialState::Booting);
    ata::AtaPioDisk driver = disk();
    boot::AtaSectorStore driverStore(driver);
    BootControl control(driverStore);
    (void)port_io_mock::takeLog();
    EXPECT_EQ(control.confirm(RunningImage::fromCommandLine("boot.slot=B boot.trial=1")), ConfirmOutcome::Confirmed);
    EXPECT_TRUE(stoppedWatchdog(port_io_mock::takeLog()));
    BootState state;
    unsigned copy = 9;
    ASSERT_TRUE(control.readState(state, copy));
    EXPECT_EQ(copy, 0u) << "the older copy was overwritten";
    EXPECT_EQ(state.sequence, 9u);
    EXPECT_EQ(state.confirmedSlot, 1);
    EXPECT_EQ(state.trial, TrialState::None);
    EXPECT_EQ(control.confirm(RunningImage::fromCommandLine("boot.slot=B")), ConfirmOutcome::AlreadyConfirmed);
}

TEST_F(BootControlTest, RefusesWhatIsNotTheCardsTrial)
{
    ata_test::FakeAtaDisk card(16384);
    putState(card, 0, 3, 0, 1, TrialState::Pending);
    ata::AtaPioDisk driver = disk();
    boot::AtaSectorStore driverStore(driver);
    BootControl control(driverStore);
    EXPECT_EQ(control.confirm(RunningImage::fromCommandLine("node=1")), ConfirmOutcome::NotFromCard);
    EXPECT_EQ(control.confirm(RunningImage::fromCommandLine("boot.slot=B boot.trial=1")), ConfirmOutcome::NotOnTrial)
        << "pending, not booting: the stage loader did not start it";
    EXPECT_EQ(control.confirm(RunningImage::fromCommandLine("boot.slot=A")), ConfirmOutcome::NotOnTrial);
    BootState state;
    unsigned copy = 0;
    ASSERT_TRUE(control.readState(state, copy));
    EXPECT_EQ(state.sequence, 3u) << "nothing written";
}

TEST_F(BootControlTest, ACardThatFailsLeavesTheTrialAndTheWatchdogRunning)
{
    ata_test::FakeAtaDisk card(16384);
    putState(card, 0, 4, 0, 1, TrialState::Booting);
    card.failWritesTo(boot::card::kBootStateLba + 1);
    ata::AtaPioDisk driver = disk();
    boot::AtaSectorStore driverStore(driver);
    BootControl control(driverStore);
    (void)port_io_mock::takeLog();
    EXPECT_EQ(control.confirm(RunningImage::fromCommandLine("boot.slot=B boot.trial=1")), ConfirmOutcome::CardError);
    EXPECT_FALSE(stoppedWatchdog(port_io_mock::takeLog()));
    BootState state;
    unsigned copy = 0;
    ASSERT_TRUE(control.readState(state, copy));
    EXPECT_EQ(state.trial, TrialState::Booting) << "still a trial: the next boot reverts";
    port_io_mock::reset();
    ata_test::FakeAtaDisk blank(16384);
    ata::AtaPioDisk other = disk();
    boot::AtaSectorStore otherStore(other);
    BootControl none(otherStore);
    EXPECT_EQ(none.confirm(RunningImage::fromCommandLine("boot.slot=A")), ConfirmOutcome::CardError)
        << "a card without a boot state";
}

} // namespace
