// Helpers for the real-time services' inline fast paths (issue 12).
#pragma once

#include <dcos/Status.hpp>

namespace dcos::internal {

/// A fast path's hand-over to the complete service, as an ordinary call
/// rather than a jump. For a tail call to a function whose arguments sit
/// elsewhere than the caller's own, GCC loads every argument in the
/// prologue, so the fast path would pay for moving the slow path's
/// arguments (a 64-bit time-out is two loads and two spills). The empty asm
/// makes the call's result pass through a register the compiler cannot see
/// through, which rules the tail call out.
template <typename Service, typename... Arguments>
[[gnu::always_inline]] inline Status callSlowPath(Service service, Arguments... arguments)
{
    Status status = service(arguments...);
    asm("" : "+r"(status));
    return status;
}

} // namespace dcos::internal
