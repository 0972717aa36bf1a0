// On-target tests, linked only into the test image (dcos486-test.elf).
//
// Each test registers with DCOS_TARGET_TEST in its own file; the 'test'
// console command lists and runs them (in the minimal kernel's test image,
// which has no console shell, the runner in minimal/ runs the one the kernel
// command line names). A test prints what it measured and
// returns whether it passed. With "--exit" the command ends the emulator
// through isa-debug-exit with the result, so the harness reads pass or fail
// from the emulator's exit status as well as from the console.
#pragma once

#include <shell/Shell.hpp>

namespace target_test {

struct TargetTest {
    const char* name;
    const char* summary;
    bool (*run)(shell::Shell& shell);
};

/// What runTargetTest found.
enum class TestOutcome { Passed, Failed, Unknown };

/// Runs the on-target test called @p name in the calling task, between its
/// "TEST <name>: start" and "TEST <name>: PASS|FAIL" lines; with @p exit the
/// emulator then ends with the result (EmulatorExit.hpp). Unknown when the
/// image has no test of that name (nothing is printed then).
TestOutcome runTargetTest(shell::Shell& shell, const char* name, bool exit);

/// Prints the image's on-target tests, one "  <name> <summary>" line each.
void listTargetTests(shell::Shell& shell);

} // namespace target_test

#define DCOS_TARGET_TEST(identifier, name, summary, function)                                     \
    [[gnu::used, gnu::section("dcos_target_tests")]] constinit const ::target_test::TargetTest \
        identifier{name, summary, function}
