// The kernel's flash service (docs/protocols/flash.md, "On CAN"; seed 8.3,
// programming and downloading): the running node takes a new image over
// the fieldbus into the card's inactive slot while its application keeps
// controlling, and restarts into it, or into the stage loader's recovery,
// when the host asks.
//
// The remote agent's receiver task hands every Flashing frame to the
// service (dcos/internal/FlashServiceHooks.hpp), which queues it for its
// own task. That task, at the least urgent priority, runs the ISO-TP
// connection and the flash session (CanFlashServer, FlashSession) on the
// card: the card writes and the signature checks take only the time the
// control tasks leave. Its replies go out through the same link, at the
// priority the host asked at, with an echo that tells the ISO-TP sender
// the frame has left.
#pragma once

#include <flash/CanFlashServer.hpp>

#include <stdint.h>

namespace flash {

/// What the console's `flash` command shows.
struct FlashServiceState {
    bool running = false;    ///< The service's task exists.
    bool fromCard = false;   ///< The node was started from its card.
    uint8_t keys = 0;        ///< Keys the card's configuration trusts.
    const char* problem = nullptr; ///< Why images cannot be taken, or null.
    uint8_t runningSlot = 0xFF;
    uint8_t interface = 0;   ///< The interface of the last connection.
    uint8_t peer = 0;        ///< Its host's CAN node number.
    uint32_t queued = 0;     ///< Frames queued for the task since boot.
    uint32_t dropped = 0;    ///< Frames dropped because the queue was full.
    uint32_t sendFailures = 0; ///< Frames the link did not take.
    CanFlashStatistics can;
};

FlashServiceState flashServiceState();

} // namespace flash
