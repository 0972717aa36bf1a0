#include <boot/BootState.hpp>
#include <boot/Crc32.hpp>

namespace boot {

namespace {

constexpr char kMagic[8] = {'D', 'C', 'O', 'S', 'B', 'O', 'O', 'T'};
constexpr uint8_t kFormat = 1;
constexpr size_t kCrcOffset = BootState::kSize - 4;

void put32(uint8_t* at, uint32_t value)
{
    for (int i = 0; i < 4; ++i) {
        at[i] = static_cast<uint8_t>(value >> (8 * i));
    }
}

uint32_t get32(const uint8_t* at)
{
    return static_cast<uint32_t>(at[0]) | (static_cast<uint32_t>(at[1]) << 8) |
           (static_cast<uint32_t>(at[2]) << 16) | (static_cast<uint32_t>(at[3]) << 24);
}

bool slotOrNone(uint8_t slot) { return slot < card::kSlotCount || slot == BootState::kNoSlot; }

} // namespace

void BootState::encode(uint8_t (&sector)[kSize]) const
{
    for (uint8_t& byte : sector) {
        byte = 0;
    }
    for (size_t i = 0; i < sizeof kMagic; ++i) {
        sector[i] = static_cast<uint8_t>(kMagic[i]);
    }
    put32(sector + 8, sequence);
    sector[12] = kFormat;
    sector[13] = confirmedSlot;
    sector[14] = trialSlot;
    sector[15] = static_cast<uint8_t>(trial);
    put32(sector + 16, reverts);
    put32(sector + kCrcOffset, crc32(sector, kCrcOffset));
}

bool BootState::decode(const uint8_t (&sector)[kSize], BootState& out)
{
    for (size_t i = 0; i < sizeof kMagic; ++i) {
        if (sector[i] != static_cast<uint8_t>(kMagic[i])) {
            return false;
        }
    }
    if (sector[12] != kFormat || get32(sector + kCrcOffset) != crc32(sector, kCrcOffset)) {
        return false;
    }
    BootState state;
    state.sequence = get32(sector + 8);
    state.confirmedSlot = sector[13];
    state.trialSlot = sector[14];
    state.trial = static_cast<TrialState>(sector[15]);
    state.reverts = get32(sector + 16);
    if (!slotOrNone(state.confirmedSlot) || !slotOrNone(state.trialSlot) || sector[15] > 2) {
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
