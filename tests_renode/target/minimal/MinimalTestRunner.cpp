// The test runner of the minimal kernel's test image (dcos486-minimal-test.elf).
//
// The minimal kernel has no console shell, so its test image cannot take a
// `test <name>` command: this application's one task runs the on-target
// test the kernel command line names instead, `test=<name>`, prints its
// result like the shell's `test` command and ends the emulator with it
// (EmulatorExit.hpp). `test=list` lists the image's tests. A shell object
// is only the tests' output: it never reads the console.
//
// The task stands where the full image's shell runs its tests: the same
// priority, stack and privilege, so that the tests see the same node.
#include "../EmulatorExit.hpp"
#include "../TargetTest.hpp"

#include <dcos/Application.hpp>

#include <boot/BootInfo.hpp>
#include <bsp/Board.hpp>
#include <runtime/Text.hpp>

namespace dcos {
const boot::BootInfo& bootInfo();
} // namespace dcos

namespace {

void runner(uintptr_t)
{
    shell::Shell output(bsp::console(), "");
    char name[24];
    if (!boot::findCommandLineOption(dcos::bootInfo().commandLine, "test", name, sizeof name) || name[0] == '\0') {
        output.print("minimal test image: name a test on the kernel command line, test=<name> or test=list\r\n");
        target_test::exitEmulator(target_test::exitFail);
    }
    if (runtime::textEquals(name, "list")) {
        target_test::listTargetTests(output);
        output.print("TEST list: done\r\n");
        target_test::exitEmulator(target_test::exitPass);
    }
    if (target_test::runTargetTest(output, name, true) == target_test::TestOutcome::Unknown) {
        output.print("error: no target test '%s' in the minimal test image; test=list shows them\r\n", name);
        target_test::exitEmulator(target_test::exitFail);
    }
}

constexpr dcos::app::TaskDeclaration tasks[] = {
    {.name = "tests", .entry = runner, .priority = dcos::internal::kShellTaskPriority,
     .stackSize = dcos::internal::kShellStackSize, .superUser = true},
};

} // namespace

DCOS_APPLICATION(minimalTestRunner, {.name = "minimal-tests", .tasks = tasks});
