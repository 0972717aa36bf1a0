// The stage loader's decision, from the card to a plan (docs/boot.md,
// "Which image boots"): from the boot state read, let BootPlanner choose
// with the caller's verification of the slots, and write the new state, if
// any, as the next record (BootStateStore), before anything boots. One function, so that the stage loader and the power-cut
// tests run the same steps.
#pragma once

#include <boot/BootPlanner.hpp>
#include <boot/BootState.hpp>
#include <boot/BootStateStore.hpp>
#include <boot/SectorStore.hpp>

namespace boot {

struct BootDecision {
    BootPlan plan;
    /// The card could not be read or the new state could not be written:
    /// the plan is Recovery then.
    bool cardFailed = false;
};

class BootSequence {
public:
    /// @p stored is what BootStateStore::read found on @p store (the
    /// caller reads it first, to report it).
    template <typename Valid>
    static BootDecision decide(SectorStore& store, const StoredBootState& stored, Valid&& valid)
    {
        BootDecision decision;
        if (!stored.readable) {
            decision.cardFailed = true;
            decision.plan.reason = "the card's boot state cannot be read";
            return decision;
        }
        decision.plan = BootPlanner::plan(stored.present ? &stored.state : nullptr, valid);
        if (decision.plan.write && !BootStateStore::writeNext(store, stored, decision.plan.state)) {
            decision.cardFailed = true;
            decision.plan.action = BootPlan::Action::Recovery;
            decision.plan.trial = false;
            decision.plan.reason = "the boot state cannot be written, so a trial could not be reverted";
        }
        return decision;
    }
};

} // namespace boot
