#include <runtime/Int64Division.hpp>

namespace runtime {

namespace {

// Counts leading zero bits of a non-zero 64-bit value. __builtin_clz on a
// 32-bit word compiles to BSR on the i486; the 64-bit builtin would pull in
// a libgcc helper, so the two halves are handled explicitly.
inline unsigned leadingZeros64(uint64_t value)
{
    const uint32_t high = static_cast<uint32_t>(value >> 32);
    if (high != 0) {
        return static_cast<unsigned>(__builtin_clz(high));
    }
    return 32u + static_cast<unsigned>(__builtin_clz(static_cast<uint32_t>(value)));
}

// Divides the 64-bit number high:low by d, where high < d, so the quotient
// fits in 32 bits. On the i486 that is exactly one DIVL (EDX:EAX / r32,
// Intel SDM Vol. 2, DIV); elsewhere (host tests) the native 64-bit divide
// gives the same result.
inline void divideTwoDigits(uint32_t high, uint32_t low, uint32_t d, uint32_t& quotient, uint32_t& remainder)
{
#if defined(__i386__)
    asm("divl %4" : "=a"(quotient), "=d"(remainder) : "a"(low), "d"(high), "rm"(d) : "cc");
#else
    const uint64_t n = (uint64_t{high} << 32) | low;
    quotient = static_cast<uint32_t>(n / d);
    remainder = static_cast<uint32_t>(n % d);
#endif
}

} // namespace

UnsignedQuotient divideUnsigned64(uint64_t dividend, uint64_t divisor)
{
    if (divisor == 0) {
        return {~uint64_t{0}, dividend};
    }
    if (dividend < divisor) {
        return {0, dividend};
    }
    // When both operands fit in 32 bits the native 32-bit divide is exact.
    if ((dividend >> 32) == 0) {
        const uint32_t n = static_cast<uint32_t>(dividend);
        const uint32_t d = static_cast<uint32_t>(divisor);
        return {n / d, n % d};
    }
    // A 32-bit divisor (the common case: nanoseconds by a tick period, a
    // calendar by 86400 s) takes two hardware divides, so the cost does not
    // depend on the values: long division in base 2^32, where each step
    // divides a two-digit number whose high digit is below the divisor.
    if ((divisor >> 32) == 0) {
        const uint32_t d = static_cast<uint32_t>(divisor);
        const uint32_t high = static_cast<uint32_t>(dividend >> 32);
        const uint32_t quotientHigh = high / d;
        const uint32_t remainderHigh = high % d;
        uint32_t quotientLow;
        uint32_t remainder;
        divideTwoDigits(remainderHigh, static_cast<uint32_t>(dividend), d, quotientLow, remainder);
        return {(uint64_t{quotientHigh} << 32) | quotientLow, remainder};
    }

    // Restoring shift-subtract division, starting at the highest bit where
    // the aligned divisor still fits under the dividend, so small quotients
    // cost few iterations.
    const unsigned shift = leadingZeros64(divisor) - leadingZeros64(dividend);
    uint64_t aligned = divisor << shift;
    uint64_t remainder = dividend;
    uint64_t quotient = 0;
    for (unsigned bit = 0; bit <= shift; ++bit) {
        quotient <<= 1;
        if (remainder >= aligned) {
            remainder -= aligned;
            quotient |= 1;
        }
        aligned >>= 1;
    }
    return {quotient, remainder};
}

SignedQuotient divideSigned64(int64_t dividend, int64_t divisor)
{
    const bool dividendNegative = dividend < 0;
    const bool divisorNegative = divisor < 0;
    // Negating through uint64_t is well defined even for INT64_MIN.
    const uint64_t n = dividendNegative ? uint64_t{0} - static_cast<uint64_t>(dividend)
                                        : static_cast<uint64_t>(dividend);
    const uint64_t d = divisorNegative ? uint64_t{0} - static_cast<uint64_t>(divisor)
                                       : static_cast<uint64_t>(divisor);
    const UnsignedQuotient u = divideUnsigned64(n, d);
    const uint64_t q = (dividendNegative != divisorNegative) ? uint64_t{0} - u.quotient : u.quotient;
    const uint64_t r = dividendNegative ? uint64_t{0} - u.remainder : u.remainder;
    return {static_cast<int64_t>(q), static_cast<int64_t>(r)};
}

} // namespace runtime
