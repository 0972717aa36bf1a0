"""The minimal kernel configuration on the emulated 486 board.

The minimal image (build/486/dcos486-minimal.elf) links only the system,
scheduler, task and timer agents and what boot needs: no console shell, no
console commands, no memory, port, DSM or semaphore agent, no application
loader, no drivers (docs/guide/kernel-configurations.md). Having no shell,
it proves itself alive with its built-in self-check application, which
prints one result line.

Its test image (dcos486-minimal-test.elf) is the same kernel with the
kernel-core on-target tests that need none of the left-out agents; a runner
application takes the test's name from the kernel command line (test=<name>)
instead of a shell command, prints the same TEST lines as the full test
image and ends the emulator with the result. Each case boots under -icount,
so every timing a test checks is exact; every wait has a time-out, and a
failure shows the console transcript (dcoslab's pytest plugin).
"""

import os
import re
import subprocess

import pytest

import test_kernel_core as kernel_core
import test_memory_protection as memory_protection
from dcoslab.board import EXIT_PASS, REPOSITORY, load_board
from dcoslab.emulator import EmulatorError
from dcoslab.target import TARGET_TEST_TIMEOUT

# The full test image's kernel-core tests that need an agent the minimal
# configuration leaves out, and why.
NEEDS_LEFT_OUT_AGENTS = {
    "recoverall": "a dying task's buffer, heap segment, semaphore and port: the memory, semaphore and port agents",
    "oddids": "the fast paths of the semaphore, port, DSM, pool and heap agents",
}

# Every kernel-core on-target test of the full test image but those above,
# and the memory protection tests: together, the minimal test image's tests.
MINIMAL_KERNEL_TARGET_TESTS = [name for name in kernel_core.KERNEL_TARGET_TESTS if name not in NEEDS_LEFT_OUT_AGENTS] \
    + memory_protection.MEMORY_PROTECTION_TARGET_TESTS

SELF_CHECKS = ["priorities and preemption", "sleep", "events", "signals", "suspend and resume", "watchdog alarm",
               "periodic alarm", "yield", "device"]


def run_minimal_target_test(emulator, name):
    """Waits for the test the kernel command line named to pass and end the emulator."""
    emulator.expect(r"kernel configuration minimal\r\n")
    emulator.expect(rf"TEST {name}: start", timeout=TARGET_TEST_TIMEOUT)
    for pattern in memory_protection.REPORTS.get(name, []):
        emulator.expect(pattern, timeout=TARGET_TEST_TIMEOUT)
    emulator.expect(rf"TEST {name}: (PASS|FAIL)", timeout=TARGET_TEST_TIMEOUT)
    assert f"TEST {name}: PASS" in emulator.transcript
    emulator.expect_exit(EXIT_PASS, timeout=TARGET_TEST_TIMEOUT)


@pytest.mark.parametrize("name", MINIMAL_KERNEL_TARGET_TESTS)
def test_minimal_kernel(boot, isa486, name):
    run_minimal_target_test(boot(isa486, "minimal-test", append=f"test={name}", icount=True), name)


def test_the_minimal_test_image_holds_exactly_the_tests_run_here(boot, isa486):
    emulator = boot(isa486, "minimal-test", append="test=list", icount=True)
    emulator.expect(r"TEST list: done", timeout=TARGET_TEST_TIMEOUT)
    emulator.expect_exit(EXIT_PASS)
    listing = emulator.transcript.split("started: 1 task", 1)[1].split("TEST list: done")[0]
    in_image = {line.split()[0] for line in listing.splitlines() if line.startswith("  ")}
    assert in_image == set(MINIMAL_KERNEL_TARGET_TESTS)


def test_the_self_check_passes(boot, isa486):
    emulator = boot(isa486, "minimal", icount=True)
    emulator.expect(r"kernel configuration minimal\r\n")
    emulator.expect(r"application 'selfcheck' started: 1 task\r\n")
    for check in SELF_CHECKS:
        emulator.expect(rf"selfcheck: {re.escape(check)}: (ok|FAILED)\r\n", timeout=TARGET_TEST_TIMEOUT)
    emulator.expect(r"SELFCHECK: (PASS|FAIL)[^\r]*\r\n", timeout=TARGET_TEST_TIMEOUT)
    assert f"SELFCHECK: PASS ({len(SELF_CHECKS)} checks)" in emulator.transcript
    assert "FAILED" not in emulator.transcript


def test_the_full_image_says_its_configuration(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(r"kernel configuration full\r\n")
    emulator.expect(r"dcos> ")


def defined_symbols(image):
    output = subprocess.run(["nm", "--defined-only", "-C", image], check=True, capture_output=True, text=True,
                            timeout=60).stdout
    return [line.split(" ", 2)[2] for line in output.splitlines() if line.count(" ") >= 2]


@pytest.mark.parametrize("kind", ["minimal", "minimal-test"])
def test_the_minimal_images_leave_out_the_agents_the_loader_and_the_drivers(kind):
    symbols = defined_symbols(load_board("isa486").image(kind))
    left_out = [r"^dcos::(SemaphoreAgent|MessagePortAgent|DsmAgent|BufferPoolAgent|HeapAgent)::",
                r"^dcos::internal::(ApplicationLoader|SemaphoreManager|PortManager|DsmManager|HeapManager|"
                r"BufferPoolManager)\b", r"^(iobus|can|sja1000|modbus)::"]
    found = [symbol for symbol in symbols if any(re.search(pattern, symbol) for pattern in left_out)]
    assert found == []
    # The agents it keeps are all there.
    for agent in ("TaskAgent", "TimerAgent", "SchedulerAgent", "SystemAgent"):
        assert any(symbol.startswith(f"dcos::{agent}::") for symbol in symbols), agent


def test_the_minimal_image_has_no_shell_and_no_console_command():
    image = load_board("isa486").image("minimal")
    symbols = defined_symbols(image)
    assert [symbol for symbol in symbols if symbol.startswith("shell::")] == []
    addresses = {}
    for line in subprocess.run(["nm", image], check=True, capture_output=True, text=True, timeout=60).stdout.splitlines():
        fields = line.split()
        if len(fields) == 3:
            addresses[fields[2]] = int(fields[0], 16)
    assert addresses["__start_dcos_shell_commands"] == addresses["__stop_dcos_shell_commands"]


# --- Applications built against the minimal kernel (the staged installation) ---

STAGED_SDK = os.path.join(REPOSITORY, "build", "sdk")
APPLICATION_MAKEFILE = os.path.join(STAGED_SDK, "share", "dcos", "application.mk")
BUILD_TIMEOUT = 600

BLINK_SOURCE = """\
#include <dcos/Application.hpp>
#include <dcos/TimerAgent.hpp>
#include <bsp/Board.hpp>
#include <runtime/Format.hpp>

namespace {
void blinker(uintptr_t)
{
    for (unsigned blink = 1; blink <= 3; ++blink) {
        if (dcos::taskAgent.SleepFor(2000000) == dcos::Status::Ok) {
            runtime::format(bsp::console(), "blink %u\\r\\n", blink);
        }
    }
}
constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "blinker", .entry = blinker, .priority = 8}};
} // namespace

DCOS_APPLICATION(blink, {.name = "blink", .tasks = tasks});
"""

BLINK_TEST = """\
def test_it_blinks(application):
    application.expect(r"blink 3")
    assert "dcos> " not in application.transcript
"""

# An application that needs the semaphore agent: by its call, or by its declaration only.
SEMAPHORE_CALL_SOURCE = """\
#include <dcos/Application.hpp>

namespace {
void user(uintptr_t)
{
    dcos::SemaphoreAttributes attributes;
    (void)dcos::semaphoreAgent.Create(attributes);
}
constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "user", .entry = user}};
} // namespace

DCOS_APPLICATION(locking, {.name = "locking", .tasks = tasks});
"""

SEMAPHORE_DECLARATION_SOURCE = """\
#include <dcos/Application.hpp>
#include <bsp/Board.hpp>
#include <runtime/Format.hpp>

namespace {
void user(uintptr_t) { runtime::format(bsp::console(), "user ran\\r\\n"); }
constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "user", .entry = user}};
constexpr dcos::app::SemaphoreDeclaration semaphores[] = {{.name = "lock"}};
} // namespace

DCOS_APPLICATION(declaring, {.name = "declaring", .tasks = tasks, .semaphores = semaphores});
"""


def write_application(directory, source, test=None):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "app.cpp"), "w", encoding="utf-8") as handle:
        handle.write(source)
    if test is not None:
        os.makedirs(os.path.join(directory, "tests"), exist_ok=True)
        with open(os.path.join(directory, "tests", "test_app.py"), "w", encoding="utf-8") as handle:
            handle.write(test)
    return directory


def build_minimal(directory, target="app"):
    return subprocess.run(["make", "--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={directory}",
                           "KERNEL_CONFIG=minimal", target], capture_output=True, text=True, timeout=BUILD_TIMEOUT)


def test_an_application_of_the_minimal_kernel_builds_runs_and_passes_its_own_tests(tmp_path):
    blink = write_application(str(tmp_path / "blink"), BLINK_SOURCE, BLINK_TEST)
    result = build_minimal(blink, "test")
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    assert re.search(r"\b1 passed\b", output), output
    image = os.path.join(blink, "build", "blink-486-minimal.elf")
    symbols = defined_symbols(image)
    assert not any(symbol.startswith(("shell::", "dcos::SemaphoreAgent::")) for symbol in symbols)


def test_a_call_to_an_agent_the_minimal_kernel_leaves_out_does_not_link(tmp_path):
    locking = write_application(str(tmp_path / "locking"), SEMAPHORE_CALL_SOURCE)
    result = build_minimal(locking)
    output = result.stdout + result.stderr
    assert result.returncode != 0, output
    assert "undefined reference to `dcos::SemaphoreAgent::Create(dcos::SemaphoreAttributes const&)'" in output
    assert not os.path.exists(os.path.join(locking, "build", "locking-486-minimal.elf"))


def test_an_application_declaring_an_object_of_a_left_out_agent_is_refused_at_boot(tmp_path, boot, isa486):
    declaring = write_application(str(tmp_path / "declaring"), SEMAPHORE_DECLARATION_SOURCE)
    result = build_minimal(declaring)
    assert result.returncode == 0, result.stdout + result.stderr
    emulator = boot(isa486, os.path.join(declaring, "build", "declaring-486-minimal.elf"), icount=True)
    emulator.expect(r"application 'declaring' not started: it declares semaphores, which the minimal kernel "
                    r"configuration leaves out\r\n")
    # Its task never runs: three seconds, a long time for the emulated board, show nothing more.
    with pytest.raises(EmulatorError, match="timed out"):
        emulator.expect(r"user ran", timeout=3)
    assert "user ran" not in emulator.transcript
