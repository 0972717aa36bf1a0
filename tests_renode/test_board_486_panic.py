"""CPU exceptions end in a panic report that shows the faulting state."""

from dcoslab.board import EXIT_PANIC

# On-target tests this module runs (see test_kernel_core.test_every_target_test_is_run).
BOARD_TARGET_TESTS = ["divzero"]


def test_divide_by_zero_reports_vector_0_with_registers(boot, isa486):
    emulator = boot(isa486, "test")
    emulator.expect(r"dcos> ")
    emulator.send("test divzero --exit\r")
    emulator.expect(r"\*\*\* DCOS PANIC: CPU exception in kernel context")
    emulator.expect(r"vector 0 \(#DE divide error\) error code 00000000")
    emulator.expect(r"EIP=[0-9a-f]{8} CS=0008 EFLAGS=[0-9a-f]{8} ESP=[0-9a-f]{8}")
    # The values the test loaded just before the faulting DIV.
    emulator.expect(r"EAX=c0ffee00 EBX=12345678 ECX=00000000 EDX=00000000")
    emulator.expect(r"ESI=5eed5eed")
    emulator.expect(r"CR0=[0-9a-f]{8} CR2=[0-9a-f]{8} CR3=[0-9a-f]{8}")
    emulator.expect(r"back trace:( [0-9a-f]{8})+")
    emulator.expect(r"\*\*\* system halted")
    emulator.expect_exit(EXIT_PANIC)
    assert "TEST divzero: PASS" not in emulator.transcript
