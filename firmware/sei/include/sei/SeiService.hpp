// The configuration protocol in a running node (docs/protocols/config.md):
// the system engineering interface agent's task
// (firmware/flash/src/FlashService.cpp) serves it beside the flash
// protocol, with the configuration key, serial number and lockout the
// card's configuration holds. This is what the console's `sei` command
// shows of it.
#pragma once

#include <sei/CanSeiServer.hpp>

#include <stdint.h>

namespace sei {

struct SeiServiceState {
    bool running = false;        ///< The agent's task serves the protocol.
    bool hasKey = false;         ///< The card's configuration holds a configuration key.
    bool queriesClosed = false;  ///< GetConfiguration needs a MAC.
    uint32_t serial = 0;         ///< The serial number a scan finds the node by (0: none).
    uint16_t lockoutSecondsLeft = 0; ///< Seconds the node still refuses changes (0: not locked out).
    unsigned badMacs = 0;        ///< Wrong MACs in a row so far.
    bool selected = false;       ///< The selected node on the broadcast address.
    CanSeiStatistics can;
};

SeiServiceState seiServiceState();

} // namespace sei
