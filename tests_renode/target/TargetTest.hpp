// On-target tests, linked only into the test image (dcos486-test.elf).
//
// Each test registers with DCOS_TARGET_TEST in its own file; the 'test'
// console command lists and runs them. A test prints what it measured and
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

} // namespace target_test

#define DCOS_TARGET_TEST(identifier, name, summary, function)                                     \
    [[gnu::used, gnu::section("dcos_target_tests")]] constinit const ::target_test::TargetTest \
        identifier{name, summary, function}
