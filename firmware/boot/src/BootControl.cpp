#include <boot/BootControl.hpp>
#include <boot/BootInfo.hpp>
#include <boot/BootStateStore.hpp>
#include <boot/TrialWatchdog.hpp>

namespace boot {

RunningImage RunningImage::fromCommandLine(const char* commandLine)
{
    RunningImage running;
    if (commandLine == nullptr) {
        return running;
    }
    char slot[4] = {};
    char flag[4] = {};
    if (findCommandLineOption(commandLine, "boot.slot", slot, sizeof slot) && (slot[0] == 'A' || slot[0] == 'B') && slot[1] == '\0') {
        running.fromCard = true;
        running.slot = static_cast<uint8_t>(slot[0] - 'A');
    }
    findCommandLineOption(commandLine, "boot.version", running.version, sizeof running.version);
    running.trial = findCommandLineOption(commandLine, "boot.trial", flag, sizeof flag) && flag[0] == '1';
    running.reverted = findCommandLineOption(commandLine, "boot.reverted", flag, sizeof flag) && flag[0] == '1';
    return running;
}

const char* confirmOutcomeText(ConfirmOutcome outcome)
{
    switch (outcome) {
    case ConfirmOutcome::Confirmed: return "confirmed: this image boots from now on, and the watchdog is stopped";
    case ConfirmOutcome::AlreadyConfirmed: return "this image is confirmed already";
    case ConfirmOutcome::NotFromCard: return "this node was not started from its card: there is nothing to confirm";
    case ConfirmOutcome::NotOnTrial: return "the card does not hold this image on trial (its boot state changed)";
    case ConfirmOutcome::CardError: return "the card's boot state cannot be read or written";
    }
    return "unknown outcome";
}

bool BootControl::readState(BootState& state, unsigned& copy)
{
    const StoredBootState stored = BootStateStore::read(store_);
    state = stored.state;
    copy = stored.copy;
    return stored.present;
}

ConfirmOutcome BootControl::confirm(const RunningImage& running)
{
    if (!running.fromCard) {
        return ConfirmOutcome::NotFromCard;
    }
    const StoredBootState stored = BootStateStore::read(store_);
    if (!stored.present) {
        return ConfirmOutcome::CardError;
    }
    BootState state = stored.state;
    if (state.trial == TrialState::None && state.confirmedSlot == running.slot) {
        return ConfirmOutcome::AlreadyConfirmed;
    }
    if (state.trial != TrialState::Booting || state.trialSlot != running.slot) {
        return ConfirmOutcome::NotOnTrial;
    }
    state.confirmedSlot = running.slot;
    state.trialSlot = BootState::kNoSlot;
    state.trial = TrialState::None;
    if (!BootStateStore::writeNext(store_, stored, state)) {
        return ConfirmOutcome::CardError;
    }
    stopWatchdog();
    return ConfirmOutcome::Confirmed;
}

void BootControl::stopWatchdog() { watchdog::stop(); }

} // namespace boot
