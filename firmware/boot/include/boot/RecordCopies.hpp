// The card keeps each of its records (the boot state, the configuration)
// in two copies, one sector each. A change goes to the older copy with the
// next sequence number; the newer valid copy is the record. A power cut
// while one copy is written leaves the other, the record as it was, and
// the torn copy fails its CRC.
#pragma once

#include <boot/CardLayout.hpp>

#include <stdint.h>

namespace boot {

/// The record two copies hold: the valid one with the higher sequence
/// (compared as a signed distance, so 0 follows 0xFFFFFFFF). @p copy is its
/// index. False when neither is valid. Record has a static
/// decode(const uint8_t (&)[512], Record&) and a uint32_t sequence.
template <typename Record>
bool newestCopy(const uint8_t (&first)[card::kSectorSize], const uint8_t (&second)[card::kSectorSize], Record& out,
                unsigned& copy)
{
    Record a;
    Record b;
    const bool aValid = Record::decode(first, a);
    const bool bValid = Record::decode(second, b);
    if (!aValid && !bValid) {
        return false;
    }
    const bool secondNewer = bValid && (!aValid || static_cast<int32_t>(b.sequence - a.sequence) > 0);
    out = secondNewer ? b : a;
    copy = secondNewer ? 1 : 0;
    return true;
}

} // namespace boot
