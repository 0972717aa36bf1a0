// Power cut at every write (issue 15): a controller's whole update, on the
// card in memory, with the power lost after exactly N writes, for every N,
// once cleanly and once tearing the cut write's first sector in half. The
// update is the real code's: the flash session downloads the new image
// (FlashSession), the stage loader decides and records its decision
// (BootSequence, verifying the slots with ImageVerifier), the new image
// confirms (BootControl), or the watchdog resets it and the next boot
// reverts. After each cut the power comes back, and:
//  - the next boot starts the old or the new image, verified, and never
//    runs the new one outside a trial unless it was confirmed;
//  - flashing can be tried again, and it ends with the newer image confirmed.
#include "FlashTestHost.hpp"

#include <boot/BootControl.hpp>
#include <boot/BootSequence.hpp>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using namespace flash_test;

constexpr uint16_t kNode = 7;

// What the stage loader finds valid: the slot's image verifies as it would
// be loaded (header in the slot's first sector, payload from its second).
bool slotVerifies(MemoryCard& store, uint8_t slot, const image::TrustedKey& key)
{
    uint8_t header[512];
    if (!store.read(card::kSlotLba[slot], 1, header)) {
        return false;
    }
    const image::ImageResult<image::ImageHeader> decoded = image::ImageHeader::decode(header, sizeof header);
    if (!decoded.ok()) {
        return false;
    }
    const uint32_t sectors = (decoded.value().payloadSize + 511) / 512;
    std::vector<uint8_t> image(header, header + 256);
    std::vector<uint8_t> payload(size_t{sectors} * 512);
    if (sectors > card::kSlotSectors - 1 || !store.read(card::kSlotLba[slot] + 1, sectors, payload.data())) {
        return false;
    }
    image.insert(image.end(), payload.begin(), payload.begin() + decoded.value().payloadSize);
    return image::ImageVerifier::verify(image.data(), image.size(), &key, 1,
                                        image::ImagePolicy::forBoard(image::BoardType::Isa486))
        .ok();
}

uint16_t versionMajorIn(MemoryCard& store, uint8_t slot)
{
    uint8_t header[512];
    EXPECT_TRUE(store.read(card::kSlotLba[slot], 1, header));
    return image::ImageHeader::decode(header, sizeof header).value().version.major;
}

struct Booted {
    bool booted = false;
    uint8_t slot = boot::BootState::kNoSlot;
    bool trial = false;
};

// One start of the controller: the stage loader's decision on the card.
Booted bootOnce(MemoryCard& store, const image::TrustedKey& key)
{
    const boot::BootDecision decision = boot::BootSequence::decide(
        store, boot::BootStateStore::read(store), [&](uint8_t slot) { return slotVerifies(store, slot, key); });
    Booted result;
    result.booted = decision.plan.action == boot::BootPlan::Action::Boot && !decision.cardFailed;
    result.slot = decision.plan.slot;
    result.trial = decision.plan.trial;
    return result;
}

// Downloads @p image over a new session; false if any step failed (the
// power went, most likely).
bool download(MemoryCard& store, const image::TrustedKey& key, const std::vector<uint8_t>& image)
{
    flash::SessionIdentity identity;
    identity.node = kNode;
    flash::FlashSession session(store, &key, 1, identity, reinterpret_cast<const uint8_t*>("cut"), 3);
    FlashHost host(session, kNode);
    return host.authenticate() == FlashStatus::Ok && host.begin(image).status == FlashStatus::Ok &&
           host.sendAll(image).status == FlashStatus::Ok && host.simple(MessageType::End).status == FlashStatus::Ok;
}

bool confirm(MemoryCard& store, const Booted& running)
{
    boot::RunningImage image;
    image.fromCard = true;
    image.slot = running.slot;
    image.trial = running.trial;
    boot::BootControl control(store);
    return control.confirm(image) == boot::ConfirmOutcome::Confirmed;
}

enum class Ending { Confirm, Revert };

// The whole update from a card whose slot A holds version 1, confirmed: the
// download of @p next, the trial boot, then a confirmation, or a boot that
// finds the trial unconfirmed and reverts. Stops at the first failure.
void update(MemoryCard& store, const image::TrustedKey& key, const std::vector<uint8_t>& next, Ending ending)
{
    if (!download(store, key, next)) {
        return;
    }
    const Booted trial = bootOnce(store, key);
    if (!trial.booted || store.cut) {
        return;
    }
    if (ending == Ending::Confirm) {
        if (!confirm(store, trial)) {
            return;
        }
        (void)bootOnce(store, key);
    } else {
        (void)bootOnce(store, key); // The watchdog reset it: the next start reverts.
    }
}

// A card with version 1 in slot A, confirmed, as dcos-card makes it.
MemoryCard freshCard(const image::TrustedKey& key, const std::vector<uint8_t>& first)
{
    MemoryCard store;
    std::copy_n(first.begin(), 256, store.bytes.begin() + card::kSlotLba[0] * 512);
    std::copy(first.begin() + 256, first.end(), store.bytes.begin() + (card::kSlotLba[0] + 1) * 512);
    boot::BootState confirmed;
    confirmed.sequence = 1;
    confirmed.confirmedSlot = 0;
    uint8_t record[512];
    confirmed.encode(record);
    std::copy(record, record + 512, store.bytes.begin() + card::kBootStateLba * 512);
    const Booted booted = bootOnce(store, key);
    EXPECT_TRUE(booted.booted && booted.slot == 0 && !booted.trial);
    store.writes = 0;
    return store;
}

void powerCutAtEveryWrite(Ending ending)
{
    const image::TrustedKey key = trusted(signingKey(0));
    const std::vector<uint8_t> first = imageOf(3000, {1, 0, 0, 0});
    const std::vector<uint8_t> second = imageOf(4500, {2, 0, 0, 0});
    const std::vector<uint8_t> third = imageOf(2000, {3, 0, 0, 0});

    MemoryCard reference = freshCard(key, first);
    update(reference, key, second, ending);
    const unsigned total = reference.writes;
    ASSERT_GE(total, 8u) << "header, five blocks, the pending state, the trial's state and the last one";
    const Booted finished = bootOnce(reference, key);
    ASSERT_TRUE(finished.booted);
    EXPECT_EQ(versionMajorIn(reference, finished.slot), ending == Ending::Confirm ? 2 : 1);

    for (unsigned budget = 0; budget < total; ++budget) {
        for (const bool tear : {false, true}) {
            SCOPED_TRACE(::testing::Message() << "power cut after " << budget << " of " << total << " writes"
                                              << (tear ? ", the next one torn" : ""));
            MemoryCard store = freshCard(key, first);
            store.budget = budget;
            store.tear = tear;
            update(store, key, second, ending);
            ASSERT_TRUE(store.cut) << "the power went";
            store.powerOn();

            // The next start runs the old or the new image, verified.
            const Booted next = bootOnce(store, key);
            ASSERT_TRUE(next.booted) << "the controller starts an image";
            const uint16_t major = versionMajorIn(store, next.slot);
            ASSERT_TRUE(major == 1 || major == 2);
            boot::BootControl control(store);
            boot::BootState state;
            unsigned copy = 0;
            ASSERT_TRUE(control.readState(state, copy));
            if (major == 2 && !next.trial) {
                EXPECT_EQ(state.confirmedSlot, next.slot) << "the new image runs outside a trial only once confirmed";
            }
            if (next.trial) {
                ASSERT_TRUE(confirm(store, next)) << "a trial that runs can confirm";
            }

            // And flashing can be tried again: a newer image, confirmed.
            const Booted settled = bootOnce(store, key);
            ASSERT_TRUE(settled.booted && !settled.trial);
            ASSERT_TRUE(download(store, key, third)) << "the retried download";
            const Booted trial = bootOnce(store, key);
            ASSERT_TRUE(trial.booted && trial.trial);
            EXPECT_EQ(versionMajorIn(store, trial.slot), 3);
            ASSERT_TRUE(confirm(store, trial));
            const Booted last = bootOnce(store, key);
            ASSERT_TRUE(last.booted && !last.trial);
            EXPECT_EQ(versionMajorIn(store, last.slot), 3);
        }
    }
}

TEST(PowerCutTest, AnUpdateThatConfirmsSurvivesAPowerCutAtEveryWrite)
{
    powerCutAtEveryWrite(Ending::Confirm);
}

TEST(PowerCutTest, AnUpdateThatRevertsSurvivesAPowerCutAtEveryWrite)
{
    powerCutAtEveryWrite(Ending::Revert);
}

} // namespace
