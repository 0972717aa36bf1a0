// What the distributed shared memory agent (seed 7.10) reports about
// itself, for the on-target tests.
#pragma once

#include <stddef.h>

namespace dcos::internal {

class DsmManager {
public:
    /// Publishers that exist.
    static size_t publisherCount();
    /// Subscriptions that are open, including those whose publisher is gone.
    static size_t subscriptionCount();
};

} // namespace dcos::internal
