// Where the kernel meets the flash service (firmware/flash/src/
// FlashService.cpp, docs/protocols/flash.md "On CAN"), in the images that
// link it: the production and test images and the SDK's library do, the
// bench and minimal images do not. Each hook is a weak symbol: in an image
// without the service it is null, and the kernel goes on without it.
#pragma once

#include <dcos/NetworkLink.hpp>
#include <dcos/Status.hpp>

#include <stdint.h>

namespace dcos::internal {

/// Starts the service: its task and the lock on the card. The root task
/// calls it once, before the application starts.
void flashServiceStart() __attribute__((weak));

/// A Flashing frame from @p interface's link, or the echo of one the
/// service sent. The remote agent's receiver task calls it, in arrival
/// order; it only queues the frame for the service's task.
void flashServiceFrame(uint8_t interface, const SystemMessage& message) __attribute__((weak));

/// Takes the card for a whole operation that reads and writes it (the
/// boot command's confirmation), so that it never interleaves with a flash
/// session's. Waits; Ok once taken.
Status cardAcquire() __attribute__((weak));
/// Gives the card back.
void cardRelease() __attribute__((weak));

/// Holds the card while it lives, when the image has the lock; nothing otherwise.
class CardHold {
public:
    CardHold() : held_(cardAcquire != nullptr && cardAcquire() == Status::Ok) {}
    ~CardHold()
    {
        if (held_) {
            cardRelease();
        }
    }
    CardHold(const CardHold&) = delete;
    CardHold& operator=(const CardHold&) = delete;

private:
    bool held_;
};

} // namespace dcos::internal
