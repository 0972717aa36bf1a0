// The stage loader's decision, from the card to a plan (docs/boot.md,
// "Which image boots"): read the boot state's two copies, let BootPlanner
// choose with the caller's verification of the slots, and write the new
// state, if any, into the copy that does not hold the state read, before
// anything boots. One function, so that the stage loader and the power-cut
// tests run the same steps.
#pragma once

#include <boot/BootPlanner.hpp>
#include <boot/BootState.hpp>
#include <boot/SectorStore.hpp>

namespace boot {

struct BootDecision {
    BootPlan plan;
    /// The state read from the card, if a copy was valid.
    bool hadState = false;
    BootState stored;
    /// The card could not be read or the new state could not be written:
    /// the plan is Recovery then.
    bool cardFailed = false;
};

class BootSequence {
public:
    template <typename Valid>
    static BootDecision decide(SectorStore& store, Valid&& valid)
    {
        BootDecision decision;
        unsigned copy = 0;
        uint8_t first[card::kSectorSize];
        uint8_t second[card::kSectorSize];
        if (!store.read(card::kBootStateLba, 1, first) || !store.read(card::kBootStateLba + 1, 1, second)) {
            decision.cardFailed = true;
            decision.plan.reason = "the card's boot state cannot be read";
            return decision;
        }
        decision.hadState = BootState::newest(first, second, decision.stored, copy);
        decision.plan = BootPlanner::plan(decision.hadState ? &decision.stored : nullptr, valid);
        if (decision.plan.write && !writeNext(store, decision, copy)) {
            decision.cardFailed = true;
            decision.plan.action = BootPlan::Action::Recovery;
            decision.plan.trial = false;
            decision.plan.reason = "the boot state cannot be written, so a trial could not be reverted";
        }
        return decision;
    }

private:
    static bool writeNext(SectorStore& store, BootDecision& decision, unsigned copy);
};

} // namespace boot
