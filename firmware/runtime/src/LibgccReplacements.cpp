// The libgcc entry points GCC calls for 64-bit division on i386.
//
// They are target-only: on the host the compiler divides natively. See
// Int64Division.hpp for why DCOS does not link the distribution's libgcc.
#include <runtime/Int64Division.hpp>

extern "C" {

uint64_t __udivdi3(uint64_t dividend, uint64_t divisor)
{
    return runtime::divideUnsigned64(dividend, divisor).quotient;
}

uint64_t __umoddi3(uint64_t dividend, uint64_t divisor)
{
    return runtime::divideUnsigned64(dividend, divisor).remainder;
}

uint64_t __udivmoddi4(uint64_t dividend, uint64_t divisor, uint64_t* remainder)
{
    const runtime::UnsignedQuotient result = runtime::divideUnsigned64(dividend, divisor);
    if (remainder != nullptr) {
        *remainder = result.remainder;
    }
    return result.quotient;
}

int64_t __divdi3(int64_t dividend, int64_t divisor)
{
    return runtime::divideSigned64(dividend, divisor).quotient;
}

int64_t __moddi3(int64_t dividend, int64_t divisor)
{
    return runtime::divideSigned64(dividend, divisor).remainder;
}

int64_t __divmoddi4(int64_t dividend, int64_t divisor, int64_t* remainder)
{
    const runtime::SignedQuotient result = runtime::divideSigned64(dividend, divisor);
    if (remainder != nullptr) {
        *remainder = result.remainder;
    }
    return result.quotient;
}

} // extern "C"
