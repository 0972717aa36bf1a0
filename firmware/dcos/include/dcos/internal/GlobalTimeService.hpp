// The global time base's kernel side (GlobalTime.hpp): what the remote
// agent's receiver task hands it.
#pragma once

#include <dcos/NetworkLink.hpp>

#include <stdint.h>

namespace dcos::internal {

/// A TimeSync message from @p interface's link (docs/protocols/time.md),
/// an echo of this node's own included. Receiver task only.
void onTimeSyncMessage(uint8_t interface, const SystemMessage& message);

} // namespace dcos::internal
