// Where things are on the controller's CompactFlash card (docs/boot.md,
// "The card"), in 512-byte sectors from LBA 0. The boot sector, the stage
// loader, the host's card builder and a running node that writes a slot
// all take their addresses from here.
#pragma once

#include <stdint.h>

namespace boot::card {

constexpr uint32_t kSectorSize = 512;

/// The BIOS loads sector 0 at 0x7C00 and runs it (the boot sector).
constexpr uint32_t kBootSectorLba = 0;
/// The stage loader: a flat binary the boot sector loads whole at kStageAddress.
constexpr uint32_t kStageLba = 1;
constexpr uint32_t kStageSectors = 255;
constexpr uint32_t kStageAddress = 0x10000;
/// The configuration block (node id, bit rate, trusted keys, command
/// line), two copies; the valid one with the higher sequence counts.
constexpr uint32_t kConfigurationLba = 256;
/// The boot state (which slot is confirmed, which is on trial), two copies
/// likewise.
constexpr uint32_t kBootStateLba = 258;
constexpr uint32_t kCopies = 2;
/// The two application slots, each an image (docs/boot.md, "Controller
/// images") of at most 2 MiB, header included.
constexpr uint32_t kSlotCount = 2;
constexpr uint32_t kSlotSectors = 4096;
constexpr uint32_t kSlotLba[kSlotCount] = {2048, 6144};
/// The smallest card that holds it all; the card images `make` builds are 8 MiB.
constexpr uint32_t kMinimumCardSectors = 10240;
constexpr uint32_t kBuiltCardSectors = 16384;

static_assert(kStageLba + kStageSectors <= kConfigurationLba, "the stage loader ends before the configuration");
static_assert(kConfigurationLba + kCopies <= kBootStateLba, "the configuration ends before the boot state");
static_assert(kBootStateLba + kCopies <= kSlotLba[0], "the boot state ends before slot A");
static_assert(kSlotLba[0] + kSlotSectors <= kSlotLba[1], "slot A ends before slot B");
static_assert(kSlotLba[1] + kSlotSectors <= kMinimumCardSectors, "slot B fits the smallest card");
static_assert(kStageAddress + kStageSectors * kSectorSize <= 0x7C000, "the stage loader stays below the stacks");

/// "A" or "B".
inline const char* slotName(uint32_t slot) { return slot == 0 ? "A" : slot == 1 ? "B" : "?"; }

} // namespace boot::card
