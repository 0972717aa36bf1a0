// Deliberate CPU exceptions in kernel context, to check the panic report.
//
// A divide error in a task is that task's exception (the task agent's
// tests cover it); in an interrupt handler it is a kernel fault, which must
// stop the node with a full report.
#include "SpareLine.hpp"
#include "TargetTest.hpp"

#include <dcos/SystemAgent.hpp>

namespace {

// An interrupt line no device uses on the emulated board; the test raises
// its vector with a software interrupt.

// Divides by zero with known values in the general registers, so the test
// can check that the report shows the state at the faulting instruction.
void divideByZeroInInterrupt(void*)
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
}

bool divideByZero(shell::Shell& shell)
{
    const dcos::Status status = dcos::systemAgent.InstallISR(target_test::spareLine(), divideByZeroInInterrupt, nullptr);
    if (status != dcos::Status::Ok) {
        shell.print("cannot install the test ISR: %s\r\n", dcos::statusName(status));
        return false;
    }
    target_test::raiseSpareLine();
    return false; // Not reached: #DE in a handler ends in the panic report.
}

} // namespace

DCOS_TARGET_TEST(divideByZeroTest, "divzero", "divide by zero in an ISR: the panic report must show vector 0",
                 divideByZero);
