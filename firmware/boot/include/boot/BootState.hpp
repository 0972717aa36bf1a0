// The card's boot state (docs/boot.md, "Which image boots"): which slot
// holds the confirmed image, and which, if any, holds a new image on
// trial. One 512-byte record, kept in two copies on the card
// (card::kBootStateLba): a change is written to the older copy with the
// next sequence number, so a power cut during the write leaves the other
// copy, the state before, valid; CRC-32 tells a torn copy.
//
//   offset size  field
//        0    8  magic "DCOSBOOT"
//        8    4  sequence (the higher of two valid copies counts)
//       12    1  format, 1
//       13    1  confirmed slot (0, 1; 0xFF none)
//       14    1  trial slot (0, 1; 0xFF none)
//       15    1  trial: 0 none, 1 pending (the next boot tries it),
//                2 booting (booted once, not confirmed yet)
//       16    4  reverts: trials that never confirmed, since the card was made
//       20    1  recovery requested: 1 = the next start stays in the stage
//                loader's recovery (a flash tool's Restart into recovery);
//                the stage loader clears it as it obeys, so it holds once
//       21  487  0
//      508    4  CRC-32 of bytes 0 to 507
#pragma once

#include <boot/CardLayout.hpp>
#include <boot/RecordCopies.hpp>

#include <stddef.h>
#include <stdint.h>

namespace boot {

enum class TrialState : uint8_t {
    None = 0,
    Pending = 1, ///< A verified new image waits in the trial slot: the next boot tries it.
    Booting = 2, ///< The trial slot was booted and has not confirmed yet.
};

struct BootState {
    static constexpr uint8_t kNoSlot = 0xFF;
    static constexpr size_t kSize = card::kSectorSize;

    uint32_t sequence = 0;
    uint8_t confirmedSlot = kNoSlot;
    uint8_t trialSlot = kNoSlot;
    TrialState trial = TrialState::None;
    uint32_t reverts = 0;
    bool recoveryRequested = false;

    void encode(uint8_t (&sector)[kSize]) const;
    /// False for anything but a whole, valid record: magic, format, CRC,
    /// slots and trial state within their ranges, a trial never in the
    /// confirmed slot.
    static bool decode(const uint8_t (&sector)[kSize], BootState& out);

    /// The state two copies hold (RecordCopies.hpp).
    static bool newest(const uint8_t (&first)[kSize], const uint8_t (&second)[kSize], BootState& out,
                       unsigned& copy)
    {
        return newestCopy(first, second, out, copy);
    }
};

} // namespace boot
