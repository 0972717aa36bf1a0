#include "EmulatorExit.hpp"
#include "KernelTestSupport.hpp"
#include "TargetTest.hpp"

#include <arch_x86/Cpu.hpp>
#include <arch_x86/PortIo.hpp>
#include <boot/Panic.hpp>
#include <bsp/Board.hpp>
#include <runtime/Text.hpp>

namespace target_test {

[[noreturn]] void exitEmulator(uint8_t code)
{
    // Everything printed must be on the line before the emulator goes.
    bsp::consoleFlush();
    arch_x86::disableInterrupts();
    arch_x86::portWrite8(debugExitPort, code);
    // Only reached when the device is missing: stop like a panic would.
    for (;;) {
        arch_x86::haltUntilInterrupt();
    }
}

extern "C" const TargetTest __start_dcos_target_tests[];
extern "C" const TargetTest __stop_dcos_target_tests[];

void listTargetTests(shell::Shell& shell)
{
    for (const TargetTest* test = __start_dcos_target_tests; test != __stop_dcos_target_tests; ++test) {
        shell.print("  %-10s %s\r\n", test->name, test->summary);
    }
}

TestOutcome runTargetTest(shell::Shell& shell, const char* name, bool exit)
{
    for (const TargetTest* test = __start_dcos_target_tests; test != __stop_dcos_target_tests; ++test) {
        if (runtime::textEquals(test->name, name)) {
            // The tests' helpers wake the task that runs them (KernelTestSupport.hpp).
            setTestTask(dcos::taskAgent.IdOfSelf());
            shell.print("TEST %s: start\r\n", test->name);
            const bool passed = test->run(shell);
            shell.print("TEST %s: %s\r\n", test->name, passed ? "PASS" : "FAIL");
            if (exit) {
                exitEmulator(passed ? exitPass : exitFail);
            }
            return passed ? TestOutcome::Passed : TestOutcome::Failed;
        }
    }
    return TestOutcome::Unknown;
}

namespace {

shell::CommandResult runTest(shell::Shell& shell, int argc, char** argv)
{
    if (argc < 2 || argc > 3 || (argc == 3 && !runtime::textEquals(argv[2], "--exit"))) {
        return shell::CommandResult::UsageError;
    }
    if (runtime::textEquals(argv[1], "list")) {
        listTargetTests(shell);
        return shell::CommandResult::Ok;
    }
    const TestOutcome outcome = runTargetTest(shell, argv[1], argc == 3);
    if (outcome == TestOutcome::Unknown) {
        shell.print("error: no target test '%s'; 'test list' shows them\r\n", argv[1]);
    }
    return outcome == TestOutcome::Passed ? shell::CommandResult::Ok : shell::CommandResult::Failed;
}

} // namespace

DCOS_SHELL_COMMAND(testCommand, "test", "run an on-target test (test image only)", "test list | test <name> [--exit]",
                   runTest);

} // namespace target_test

// In the test image a panic also ends the emulator, so the harness sees it
// at once instead of waiting for a time-out.
extern "C" [[noreturn]] void dcosPanicHalt()
{
    target_test::exitEmulator(target_test::exitPanic);
}
