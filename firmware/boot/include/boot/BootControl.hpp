// What a running node knows and does about the image it runs (docs/boot.md,
// "Confirming a trial"): where it came from, as the stage loader put it on
// the kernel's command line, and the confirmation that makes a trial image
// the confirmed one and stops the watchdog. Used by the console's `boot`
// command and by applications that confirm themselves once they have
// shown they work.
#pragma once

#include <boot/BootState.hpp>
#include <boot/SectorStore.hpp>

#include <stdint.h>

namespace boot {

/// The image this node runs, from the stage loader's words on the command
/// line (boot.slot, boot.version, boot.trial, boot.reverted).
struct RunningImage {
    bool fromCard = false;
    uint8_t slot = BootState::kNoSlot;
    bool trial = false;
    bool reverted = false;
    char version[32] = {};

    static RunningImage fromCommandLine(const char* commandLine);
};

enum class ConfirmOutcome : uint8_t {
    Confirmed,        ///< The trial is now the confirmed image; the watchdog is stopped.
    AlreadyConfirmed, ///< The running image was confirmed already.
    NotFromCard,      ///< The node was not started from its card (a development boot).
    NotOnTrial,       ///< The card's state does not hold this image on trial (changed meanwhile).
    CardError,        ///< The card cannot be read or written, or holds no boot state.
};

/// One line for an engineer.
const char* confirmOutcomeText(ConfirmOutcome outcome);

class BootControl {
public:
    explicit BootControl(SectorStore& store) : store_(store) {}

    /// The card's boot state; false when the card cannot be read or holds none.
    bool readState(BootState& state, unsigned& copy);

    /// Confirms @p running if it is the card's trial: writes the new state
    /// (to the older copy, RecordCopies.hpp), then stops the watchdog. If the
    /// write fails the trial stays a trial, and the watchdog runs on.
    ConfirmOutcome confirm(const RunningImage& running);

    /// Stops the board's IB700-compatible watchdog (a write to port 0x441).
    static void stopWatchdog();

private:
    SectorStore& store_;
};

} // namespace boot
