"""The freestanding runtime on the emulated i486: what the host tests cannot reach."""

from dcoslab.board import EXIT_PASS

# On-target tests this module runs (see test_kernel_core.test_every_target_test_is_run).
RUNTIME_TARGET_TESTS = ["div64"]


def test_64_bit_division_uses_divl_correctly(boot, isa486):
    emulator = boot(isa486, "test")
    emulator.expect(r"dcos> ")
    emulator.send("test div64 --exit\r")
    emulator.expect(r"4000 random divisions: 0 wrong; known values right")
    emulator.expect_exit(EXIT_PASS)
