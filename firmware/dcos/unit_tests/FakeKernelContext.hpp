// A scriptable stand-in for the task agent's KernelContext, for host tests.
//
// FakeKernelContext.cpp defines currentTaskId, currentTaskIsSuperUser,
// inInterruptContext and localNode (dcos/internal/KernelContext.hpp) for the
// host test binary only; the firmware gets the task agent's definitions.
// Tests use the functions below to play a super user, a user task or an
// interrupt handler, and call reset() first so that no test depends on
// another's leftovers.
#pragma once

#include <dcos/ObjectId.hpp>

#include <stdint.h>

namespace dcos::fake {

/// The node id reset() restores.
inline constexpr uint16_t kDefaultNode = 1;

/// Restores the defaults: node kDefaultNode, a user task (Task index 1) running, no interrupt.
void reset();

/// Makes @p task the running task, with super-user privilege.
void playSuperUser(ObjectId task);

/// Makes @p task the running task, without super-user privilege.
void playUserTask(ObjectId task);

/// Enters (true) or leaves (false) interrupt context; the running task stays the interrupted one.
void setInInterrupt(bool inInterrupt);

/// Sets the node id this controller reports.
void setLocalNode(uint16_t node);

} // namespace dcos::fake
