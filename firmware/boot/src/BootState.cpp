#include <boot/BootState.hpp>
#include <boot/RecordSector.hpp>

namespace boot {

namespace {

using record::get32;
using record::put32;

constexpr char kMagic[8] = {'D', 'C', 'O', 'S', 'B', 'O', 'O', 'T'};
constexpr uint8_t kFormat = 1;

bool slotOrNone(uint8_t slot) { return slot < card::kSlotCount || slot == BootState::kNoSlot; }

} // namespace

void BootState::encode(uint8_t (&sector)[kSize]) const
{
    record::begin(sector, kMagic, sequence, kFormat);
    sector[13] = confirmedSlot;
    sector[14] = trialSlot;
    sector[15] = static_cast<uint8_t>(trial);
    put32(sector + 16, reverts);
    sector[20] = recoveryRequested ? 1 : 0;
    record::seal(sector);
}

bool BootState::decode(const uint8_t (&sector)[kSize], BootState& out)
{
    if (!record::intact(sector, kMagic, kFormat)) {
        return false;
    }
    BootState state;
    state.sequence = get32(sector + record::kSequenceOffset);
    state.confirmedSlot = sector[13];
    state.trialSlot = sector[14];
    state.trial = static_cast<TrialState>(sector[15]);
    state.reverts = get32(sector + 16);
    state.recoveryRequested = sector[20] == 1;
    if (!slotOrNone(state.confirmedSlot) || !slotOrNone(state.trialSlot) || sector[15] > 2 || sector[20] > 1) {
        return false;
    }
    const bool trialNamed = state.trial != TrialState::None;
    if (trialNamed != (state.trialSlot != kNoSlot) ||
        (trialNamed && state.trialSlot == state.confirmedSlot)) {
        return false;
    }
    out = state;
    return true;
}

} // namespace boot
