// Helpers for the real-time services' inline fast paths (issue 12).
#pragma once

#include <dcos/Status.hpp>

#include <stdint.h>

namespace dcos::internal {

/// A fast path's hand-over to the complete service, as an ordinary call
/// rather than a jump. For a tail call to a function whose arguments sit
/// elsewhere than the caller's own, GCC loads every argument in the
/// prologue, so the fast path would pay for moving the slow path's
/// arguments (a 64-bit time-out is two loads and two spills). The empty asm
/// makes the call's result pass through a register the compiler cannot see
/// through, which rules the tail call out. A 64-bit time-out is best passed
/// by address: by value, GCC loads both its words into registers on entry,
/// which costs the fast path the registers it needs (Acquire, Receive and
/// Read pass it so).
template <typename Service, typename... Arguments>
[[gnu::always_inline]] inline Status callSlowPath(Service service, Arguments... arguments)
{
    Status status = service(arguments...);
    asm("" : "+r"(status));
    return status;
}

/// A 64-bit time-out spilled by a fast path for its slow path, which takes
/// it by address (see callSlowPath). Two 32-bit words: the firmware keeps
/// its stack 4-byte aligned (-mpreferred-stack-boundary=2, mk/firmware.mk),
/// and a uint64_t local whose address is taken makes GCC realign the frame
/// to 8 bytes through a frame pointer, four instructions on every call.
class SpilledTimeout {
public:
    [[gnu::always_inline]] explicit SpilledTimeout(uint64_t timeout)
        : low_(static_cast<uint32_t>(timeout)), high_(static_cast<uint32_t>(timeout >> 32))
    {
    }
    uint64_t value() const { return (static_cast<uint64_t>(high_) << 32) | low_; }

private:
    uint32_t low_;
    uint32_t high_;
};

/// Copies 16 bytes (a port message, a DSM page) as four words. Those are
/// arrays of bytes, so a plain assignment is a copy of unknown alignment,
/// which GCC makes a REP MOVS with its set-up around it (tuned for the
/// i486), twice as long as this; into an aligned destination it is a short
/// REP MOVSL, as long as this.
[[gnu::always_inline]] inline void copySixteenBytes(void* to, const void* from)
{
    uint32_t a, b, c, d;
    const uint8_t* source = static_cast<const uint8_t*>(from);
    uint8_t* destination = static_cast<uint8_t*>(to);
    __builtin_memcpy(&a, source, 4);
    __builtin_memcpy(&b, source + 4, 4);
    __builtin_memcpy(&c, source + 8, 4);
    __builtin_memcpy(&d, source + 12, 4);
    __builtin_memcpy(destination, &a, 4);
    __builtin_memcpy(destination + 4, &b, 4);
    __builtin_memcpy(destination + 8, &c, 4);
    __builtin_memcpy(destination + 12, &d, 4);
}

} // namespace dcos::internal
