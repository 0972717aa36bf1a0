// Deliberate CPU exceptions, to check the panic report.
#include "TargetTest.hpp"

namespace {

// Divides by zero with known values in the general registers, so the test
// can check that the report shows the state at the faulting instruction.
bool divideByZero(shell::Shell&)
{
    asm volatile(
        "movl $0xC0FFEE00, %%eax\n\t"
        "movl $0x12345678, %%ebx\n\t"
        "xorl %%ecx, %%ecx\n\t"
        "xorl %%edx, %%edx\n\t"
        "movl $0x5EED5EED, %%esi\n\t"
        "divl %%ecx\n\t"
        :
        :
        : "eax", "ebx", "ecx", "edx", "esi", "memory", "cc");
    return false; // Not reached: #DE ends in the panic report.
}

} // namespace

DCOS_TARGET_TEST(divideByZeroTest, "divzero", "divide by zero: the panic report must show vector 0", divideByZero);
