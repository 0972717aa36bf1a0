// 64-bit integer division for a 32-bit freestanding target.
//
// GCC lowers a 64-bit '/' or '%' on i386 into calls to __udivdi3 and friends,
// which normally come from libgcc. Debian's 32-bit libgcc is built for i686
// and contains CMOV, which an i486 does not have, so DCOS never links it and
// supplies these routines itself. The arithmetic lives here in portable C++
// so that the host unit tests can compare it with the compiler's own
// division; the libgcc-named entry points are thin target-only wrappers.
#pragma once

#include <stdint.h>

namespace runtime {

/// Result of an unsigned 64-bit division.
struct UnsignedQuotient {
    uint64_t quotient;
    uint64_t remainder;
};

/// Divides an unsigned 64-bit number by a non-zero unsigned 64-bit divisor.
///
/// Uses only 32-bit operations and shifts, so it compiles to plain i486
/// code. The loop runs at most once per significant bit of the dividend
/// beyond the divisor's width: at most 64 iterations. A zero divisor is a
/// programming error; it yields a quotient of all ones and the dividend as
/// remainder, the same convention the hardware would break with #DE.
UnsignedQuotient divideUnsigned64(uint64_t dividend, uint64_t divisor);

/// Signed 64-bit division, truncating towards zero as C++ requires.
/// The remainder takes the sign of the dividend.
struct SignedQuotient {
    int64_t quotient;
    int64_t remainder;
};

/// Divides a signed 64-bit number by a non-zero signed 64-bit divisor.
SignedQuotient divideSigned64(int64_t dividend, int64_t divisor);

} // namespace runtime
