// Decides which image boots (docs/boot.md, "Which image boots"), from the
// card's boot state and whether each slot holds a valid image. Pure: the
// stage loader reads the card and verifies the slots, this decides, the
// stage loader writes the new state (before it boots, so that a boot that
// never returns is already counted) and jumps.
//
//  - A pending trial whose image is valid boots, as a trial: its state
//    becomes "booting" and the watchdog is armed. If it is invalid, the
//    trial is dropped.
//  - A trial still "booting" at the next boot never confirmed: it is
//    reverted, and the confirmed image boots.
//  - Otherwise the confirmed image boots. If it is invalid (the card
//    decayed), the other slot's valid image boots and becomes confirmed,
//    unless it is a trial dropped on this boot.
//  - With no confirmed image at all, the first valid one boots as a trial.
//  - With no valid image at all, the stage loader stays in recovery.
//
// Slots are verified only when the decision needs them, in that order.
#pragma once

#include <boot/BootState.hpp>

#include <stdint.h>

namespace boot {

struct BootPlan {
    enum class Action : uint8_t { Boot, Recovery };

    Action action = Action::Recovery;
    uint8_t slot = BootState::kNoSlot;
    /// Booting a trial: arm the watchdog; the image must confirm.
    bool trial = false;
    /// A trial was reverted (never confirmed, or invalid) on this boot.
    bool reverted = false;
    /// The state to write before booting; write only when @p write.
    bool write = false;
    BootState state;
    /// One line for the console: why this image, or why none.
    const char* reason = "";
};

class BootPlanner {
public:
    /// @p stored is the card's state, null when neither copy is valid (a
    /// new card). @p valid(slot) verifies a slot's image; it is called at
    /// most once per slot.
    template <typename Valid>
    static BootPlan plan(const BootState* stored, Valid&& valid)
    {
        Verdicts verdicts;
        return decide(stored, [&](uint8_t slot) { return verdicts.of(slot, valid); });
    }

private:
    struct Verdicts {
        int8_t known[card::kSlotCount] = {-1, -1};

        template <typename Valid>
        bool of(uint8_t slot, Valid& valid)
        {
            if (known[slot] < 0) {
                known[slot] = valid(slot) ? 1 : 0;
            }
            return known[slot] == 1;
        }
    };

    template <typename Valid>
    static BootPlan decide(const BootState* stored, Valid&& valid);
};

template <typename Valid>
BootPlan BootPlanner::decide(const BootState* stored, Valid&& valid)
{
    BootPlan plan;
    plan.state = stored != nullptr ? *stored : BootState{};
    BootState& state = plan.state;
    plan.write = stored == nullptr;
    // A trial that is dropped here never becomes the fallback below: an
    // image that did not confirm may hang, and recovery is reachable.
    const uint8_t dropped = state.trial != TrialState::None ? state.trialSlot : BootState::kNoSlot;
    if (state.trial == TrialState::Pending) {
        if (valid(state.trialSlot)) {
            state.trial = TrialState::Booting;
            plan.action = BootPlan::Action::Boot;
            plan.slot = state.trialSlot;
            plan.trial = true;
            plan.write = true;
            plan.reason = "a new image on trial: it must confirm before the watchdog expires";
            return plan;
        }
        plan.reason = "the new image is not valid: its trial is dropped";
        plan.reverted = true;
    } else if (state.trial == TrialState::Booting) {
        plan.reason = "the new image never confirmed: reverted to the confirmed one";
        plan.reverted = true;
    }
    if (plan.reverted) {
        state.trial = TrialState::None;
        state.trialSlot = BootState::kNoSlot;
        ++state.reverts;
        plan.write = true;
    }
    if (state.confirmedSlot != BootState::kNoSlot && valid(state.confirmedSlot)) {
        plan.action = BootPlan::Action::Boot;
        plan.slot = state.confirmedSlot;
        if (!plan.reverted) {
            plan.reason = "the confirmed image";
        }
        return plan;
    }
    // No confirmed image, or it no longer verifies: the first valid slot,
    // the other one first when a confirmed slot failed. An image nothing
    // ever confirmed (a download cut short before it was marked pending,
    // say) boots only as a trial: it must confirm, or it is dropped. The
    // other slot of a confirmed image that decayed held the image confirmed
    // before it, and boots confirmed.
    const bool noneConfirmed = state.confirmedSlot == BootState::kNoSlot;
    const uint8_t first = noneConfirmed ? 0 : static_cast<uint8_t>(state.confirmedSlot ^ 1);
    for (uint8_t i = 0; i < card::kSlotCount; ++i) {
        const uint8_t slot = static_cast<uint8_t>((first + i) % card::kSlotCount);
        if (slot != state.confirmedSlot && slot != dropped && valid(slot)) {
            plan.action = BootPlan::Action::Boot;
            plan.slot = slot;
            plan.write = true;
            if (noneConfirmed) {
                plan.trial = true;
                state.trial = TrialState::Booting;
                state.trialSlot = slot;
                plan.reason = "no confirmed image: a valid one on trial: it must confirm before the watchdog expires";
            } else {
                state.confirmedSlot = slot;
                plan.reason = "the confirmed image is no longer valid: the other slot's, now confirmed";
            }
            return plan;
        }
    }
    plan.action = BootPlan::Action::Recovery;
    plan.slot = BootState::kNoSlot;
    plan.reason = "no valid image on the card: recovery";
    return plan;
}

} // namespace boot
