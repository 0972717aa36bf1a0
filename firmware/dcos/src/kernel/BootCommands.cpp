// The `boot` console command (docs/boot.md, "Confirming a trial"): which
// image the node runs and from where, the card's boot state, and the
// confirmation of a trial image.
//
//   boot            the running image, and the card's boot state
//   boot confirm    make the running trial image the confirmed one
#include <boot/AtaSectorStore.hpp>
#include <boot/BootControl.hpp>
#include <boot/BootInfo.hpp>
#include <boot/CardLayout.hpp>
#include <dcos/internal/FlashServiceHooks.hpp>
#include <runtime/Text.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace dcos {

namespace {

const char* trialText(boot::TrialState trial)
{
    switch (trial) {
    case boot::TrialState::None: return "none";
    case boot::TrialState::Pending: return "pending";
    case boot::TrialState::Booting: return "booting";
    }
    return "?";
}

shell::CommandResult bootCommand(shell::Shell& shell, int argc, char** argv)
{
    const boot::RunningImage running = boot::RunningImage::fromCommandLine(bootInfo().commandLine);
    ata::AtaPioDisk disk = ata::AtaPioDisk::primary();
    boot::AtaSectorStore store(disk);
    boot::BootControl control(store);
    // A flash session over CAN may be writing the same boot state.
    const internal::CardHold hold;
    if (argc == 2 && runtime::textEquals(argv[1], "confirm")) {
        const boot::ConfirmOutcome outcome = control.confirm(running);
        shell.print("boot: %s\r\n", boot::confirmOutcomeText(outcome));
        return outcome == boot::ConfirmOutcome::Confirmed || outcome == boot::ConfirmOutcome::AlreadyConfirmed
                   ? shell::CommandResult::Ok
                   : shell::CommandResult::Failed;
    }
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    if (!running.fromCard) {
        shell.print("boot: started by %s, not from the card\r\n", bootInfo().loaderName);
        return shell::CommandResult::Ok;
    }
    shell.print("boot: slot %s, version %s%s%s\r\n", boot::card::slotName(running.slot), running.version,
                running.trial ? ", on trial: confirm with 'boot confirm' before the watchdog expires" : "",
                running.reverted ? ", after a trial that never confirmed was reverted" : "");
    boot::BootState state;
    unsigned copy = 0;
    if (!control.readState(state, copy)) {
        shell.print("boot: the card's boot state cannot be read\r\n");
        return shell::CommandResult::Failed;
    }
    shell.print("card: boot state %lu (copy %u): confirmed slot %s, trial %s%s%s, %lu revert%s\r\n",
                static_cast<unsigned long>(state.sequence), copy, boot::card::slotName(state.confirmedSlot),
                trialText(state.trial), state.trial != boot::TrialState::None ? " in slot " : "",
                state.trial != boot::TrialState::None ? boot::card::slotName(state.trialSlot) : "",
                static_cast<unsigned long>(state.reverts), state.reverts == 1 ? "" : "s");
    return shell::CommandResult::Ok;
}

} // namespace

} // namespace dcos

DCOS_SHELL_COMMAND(bootCommandEntry, "boot", "show the running image and the card's boot state; confirm a trial",
                   "boot [confirm]", dcos::bootCommand);
