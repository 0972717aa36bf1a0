// Recovery of the objects a task still owns when it ends.
//
// Each agent registers one recovery function with DCOS_RESOURCE_RECOVERY in
// its own source file. When a task ends (Delete, KillTask or a fatal
// exception), the task agent calls every registered function with the dead
// task's id, and each agent releases or deletes what that task owned. The
// linker gathers the functions into the section dcos_resource_recovery, so
// the task agent needs no list of agents.
#pragma once

#include <dcos/ObjectId.hpp>

namespace dcos::internal {

struct ResourceRecovery {
    /// The agent, for diagnostics.
    const char* agent;
    /// Releases everything deadTask owns; returns how many objects it recovered.
    unsigned (*recover)(ObjectId deadTask);
};

/// Runs every registered recovery function; returns the objects recovered.
unsigned recoverResourcesOf(ObjectId deadTask);

} // namespace dcos::internal

#define DCOS_RESOURCE_RECOVERY(identifier, agent, function)                                                \
    [[gnu::used, gnu::section("dcos_resource_recovery")]] constinit const ::dcos::internal::ResourceRecovery \
        identifier{agent, function}
