#include <boot/BootControl.hpp>

#include <arch_x86/PortIo.hpp>

namespace boot {

namespace {

constexpr uint16_t kWatchdogStop = 0x441; // IB700: a write stops the timer (StageLoader.cpp arms it).

// The value of "key=" in a space-separated command line, copied into
// @p value; false when the key is absent.
bool option(const char* line, const char* key, char* value, size_t capacity)
{
    for (const char* at = line; *at != '\0';) {
        while (*at == ' ') {
            ++at;
        }
        const char* word = at;
        size_t i = 0;
        while (key[i] != '\0' && word[i] == key[i]) {
            ++i;
        }
        if (key[i] == '\0' && word[i] == '=') {
            const char* text = word + i + 1;
            size_t length = 0;
            while (text[length] != '\0' && text[length] != ' ' && length + 1 < capacity) {
                value[length] = text[length];
                ++length;
            }
            value[length] = '\0';
            return true;
        }
        while (*at != '\0' && *at != ' ') {
            ++at;
        }
    }
    return false;
}

} // namespace

RunningImage RunningImage::fromCommandLine(const char* commandLine)
{
    RunningImage running;
    if (commandLine == nullptr) {
        return running;
    }
    char slot[4] = {};
    char flag[4] = {};
    if (option(commandLine, "boot.slot", slot, sizeof slot) && (slot[0] == 'A' || slot[0] == 'B') && slot[1] == '\0') {
        running.fromCard = true;
        running.slot = static_cast<uint8_t>(slot[0] - 'A');
    }
    option(commandLine, "boot.version", running.version, sizeof running.version);
    running.trial = option(commandLine, "boot.trial", flag, sizeof flag) && flag[0] == '1';
    running.reverted = option(commandLine, "boot.reverted", flag, sizeof flag) && flag[0] == '1';
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
    uint8_t first[card::kSectorSize];
    uint8_t second[card::kSectorSize];
    return store_.read(card::kBootStateLba, 1, first) && store_.read(card::kBootStateLba + 1, 1, second) &&
           BootState::newest(first, second, state, copy);
}

ConfirmOutcome BootControl::confirm(const RunningImage& running)
{
    if (!running.fromCard) {
        return ConfirmOutcome::NotFromCard;
    }
    BootState state;
    unsigned copy = 0;
    if (!readState(state, copy)) {
        return ConfirmOutcome::CardError;
    }
    if (state.trial == TrialState::None && state.confirmedSlot == running.slot) {
        return ConfirmOutcome::AlreadyConfirmed;
    }
    if (state.trial != TrialState::Booting || state.trialSlot != running.slot) {
        return ConfirmOutcome::NotOnTrial;
    }
    state.confirmedSlot = running.slot;
    state.trialSlot = BootState::kNoSlot;
    state.trial = TrialState::None;
    ++state.sequence;
    uint8_t record[card::kSectorSize];
    state.encode(record);
    if (!store_.write(card::kBootStateLba + (copy ^ 1u), 1, record)) {
        return ConfirmOutcome::CardError;
    }
    stopWatchdog();
    return ConfirmOutcome::Confirmed;
}

void BootControl::stopWatchdog() { arch_x86::portWrite8(kWatchdogStop, 0); }

} // namespace boot
