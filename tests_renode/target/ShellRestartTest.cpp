// A fatal exception in the console shell itself: the shell task ends like
// any other task, and the root task starts a new shell (Kernel.cpp). Run by
// tests_renode/test_console_restart.py, which checks the console comes back.
#include "TargetTest.hpp"

#include <stdint.h>

namespace target_test {

namespace {

// A selector beyond the end of the GDT: loading it raises a general
// protection fault (#GP, a fatal exception) in the task that runs the
// command, which is the shell.
constexpr uint16_t kSelectorBeyondTheGdt = 0xFFF8;

bool faultInTheShell(shell::Shell& shell)
{
    shell.print("loading selector 0x%04x into DS in the shell task\r\n", kSelectorBeyondTheGdt);
    asm volatile("movw %0, %%ds" : : "r"(kSelectorBeyondTheGdt) : "memory");
    shell.print("the shell was not stopped by the fault\r\n");
    return false;
}

} // namespace

DCOS_TARGET_TEST(shellFaultTest, "shellfault", "a fatal exception in the shell; the console starts a new one",
                 faultInTheShell);

} // namespace target_test
