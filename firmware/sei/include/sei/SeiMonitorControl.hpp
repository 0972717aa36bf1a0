// What the configuration protocol's Monitor command (docs/protocols/config.md)
// asks of the node: start, renew or stop the stream of samples and console
// output to the host that asked. The running node's stream lives in the
// system engineering interface agent's task (firmware/flash/src/FlashService.cpp),
// which implements this; SeiNodeBackend hands Monitor requests to it.
#pragma once

#include <sei/SeiMessage.hpp>

#include <stdint.h>

namespace sei {

class SeiMonitorControl {
public:
    /// Applies @p request (a decoded, admitted Monitor request) at @p nowNs:
    /// its channels replace the stream's, its lease runs from now, and a
    /// lease of 0 stops the stream. Returns the kernel's dcos::Status as a
    /// value: 0 when done, otherwise why not (a channel that names no
    /// publisher of this node: InvalidId, StaleId or WrongType), and then
    /// the stream is as it was.
    virtual uint8_t configure(const SeiMessage& request, uint64_t nowNs) = 0;

protected:
    ~SeiMonitorControl() = default;
};

} // namespace sei
