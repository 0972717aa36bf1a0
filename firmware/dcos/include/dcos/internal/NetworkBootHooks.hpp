// Where the kernel starts the fieldbus links its command line names
// (docs/boot.md, "What the kernel takes from the command line"), in the
// images that link the CAN console (drivers/can/src/CanCommands.cpp): the
// production and test images and the SDK's library do, the bench and
// minimal images do not. The hook is a weak symbol: in an image without the
// links it is null, and the kernel goes on without them.
#pragma once

namespace dcos::internal {

/// Brings up every CAN channel the command line names ("can0=RATE",
/// "can1=RATE") at that bit rate and attaches it to the network as an
/// interface of its own: address 130.<channel + 1>.0.<node>/16, the node id
/// as CAN node number. The root task calls it once, after the flash
/// service starts and before the application does. A channel it cannot
/// start is reported on the console and left down; the node runs on.
void networkBootStart() __attribute__((weak));

/// Brings up the network the board itself has between its nodes (the
/// dual-Pentium board's shared memory, firmware/bsp_p5smp) and attaches it
/// as an interface; called by the root task right after networkBootStart.
/// Null on a board without one.
void boardNetworkStart() __attribute__((weak));

/// Switches every CAN channel that is up, and not at @p rate bit/s already,
/// to @p rate at once, as the
/// configuration protocol's ActivateBitRate asks (docs/protocols/config.md,
/// "Switching the bus's bit rate"); says so on the console. A channel the
/// chip cannot run at @p rate is left as it was, and said so too.
void switchCanBitRate(uint32_t rate) __attribute__((weak));

} // namespace dcos::internal
