"""Running the test image's on-target tests from an emulator test."""

from .board import EXIT_PASS

# Generous: bounds a hung test, it does not measure speed.
TARGET_TEST_TIMEOUT = 120.0


def run_target_test(emulator, name, timeout=TARGET_TEST_TIMEOUT):
    """Runs `test <name> --exit` on a booted test image and checks it passed.

    The test prints what it measured; its PASS or FAIL line and the
    emulator's isa-debug-exit status must both say pass. A failure raises
    with the console transcript. Returns the emulator for further checks.
    """
    emulator.expect(r"dcos> ")
    emulator.send(f"test {name} --exit\r")
    emulator.expect(rf"TEST {name}: (PASS|FAIL)", timeout=timeout)
    emulator.expect_exit(EXIT_PASS, timeout=timeout)
    return emulator
