// The node's side of the flash protocol (docs/protocols/flash.md): takes
// requests, one at a time, and answers them, writing the image into the
// card's inactive slot. The same code serves the stage loader in recovery
// (over the serial line); the card is reached through FlashStore, so the
// whole session runs in the host tests on a card in memory.
//
// A session opens with Hello, which draws a fresh challenge, and
// Authenticate, the challenge signed with a key the card trusts; a
// challenge is good for one attempt. Begin checks the image's header as the
// stage loader will check the slot (signature, board, size, memory, no
// downgrade below the confirmed image) and names the slot; it writes the
// header there and clears a trial that slot held. Data blocks follow in
// order, each with its sequence number and CRC; a Begin with the same
// header resumes where the last block ended. End reads the slot back, checks
// the payload's digest and only then marks the slot pending. Restart asks
// the caller to restart the node, which then tries the image as a trial;
// Restart into recovery first marks the boot state so that the stage
// loader stays in recovery on that one start (BootState::recoveryRequested).
#pragma once

#include <flash/FlashMessage.hpp>

#include <boot/BootState.hpp>
#include <boot/SectorStore.hpp>
#include <image/ImageVerifier.hpp>

#include <stddef.h>
#include <stdint.h>

namespace flash {

/// The card, as the session reads and writes it (boot/SectorStore.hpp).
using FlashStore = boot::SectorStore;

struct SessionIdentity {
    uint16_t node = 0;
    image::BoardType board = image::BoardType::Isa486;
    NodeMode mode = NodeMode::Recovery;
    /// Where the node's memory ends: an image must fit below it.
    uint32_t memoryEnd = 16u << 20;
    /// The slot the running application was loaded from (the boot.slot of
    /// its command line); kNoSlot in recovery, or when it was not started
    /// from the card. Begin never writes into it.
    uint8_t runningSlot = boot::BootState::kNoSlot;
};

class FlashSession {
public:
    /// @p seed makes the challenges unique to this node and start: bytes
    /// that differ from one start to the next (the clock, the tick
    /// counter). They need not be secret; the challenge is the digest of
    /// the seed and a count of Hellos.
    FlashSession(FlashStore& store, const image::TrustedKey* keys, size_t keyCount, const SessionIdentity& identity,
                 const uint8_t* seed, size_t seedLength);

    /// Answers one request of @p length bytes; the reply's length (0 if
    /// @p capacity is too small). Malformed requests get a Malformed reply.
    size_t handle(const uint8_t* request, size_t length, uint8_t* reply, size_t capacity);

    /// True, with the target, once a Restart was answered: the caller
    /// sends the reply and then restarts the node.
    bool restartRequested(RestartTarget& target) const
    {
        target = restartTarget_;
        return restartRequested_;
    }

private:
    FlashStatus hello(FlashMessage& reply);
    FlashStatus authenticate(const FlashMessage& request);
    FlashStatus begin(const FlashMessage& request, FlashMessage& reply);
    FlashStatus data(const FlashMessage& request, FlashMessage& reply);
    FlashStatus end(FlashMessage& reply);
    FlashStatus requestRecovery();
    bool slotHeader(uint8_t slot, image::ImageHeader& header);

    FlashStore& store_;
    const image::TrustedKey* keys_;
    size_t keyCount_;
    SessionIdentity identity_;
    uint8_t seed_[32] = {};
    uint32_t hellos_ = 0;

    uint8_t challenge_[kChallengeSize] = {};
    bool challengeFresh_ = false;
    bool authenticated_ = false;

    // The transfer: the header Begin accepted, the slot, and the progress.
    bool transferring_ = false;
    bool transferComplete_ = false;
    uint8_t headerBytes_[image::ImageHeader::kSize] = {};
    image::ImageHeader header_;
    uint8_t slot_ = boot::BootState::kNoSlot;
    uint32_t progress_ = 0;
    uint32_t sequence_ = 0;

    bool restartRequested_ = false;
    RestartTarget restartTarget_ = RestartTarget::Boot;
};

} // namespace flash
