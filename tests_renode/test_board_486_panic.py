"""CPU exceptions end in a panic report that shows the faulting state."""

import re

from dcoslab.board import EXIT_PANIC
from dcoslab.symbolize import symbolize

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
    back_trace = emulator.expect(r"back trace:((?: [0-9a-f]{8})+)\r\n")  # The whole line.
    trace = [int(word, 16) for word in back_trace.group(1).split()]
    emulator.expect(r"\*\*\* system halted")
    emulator.expect_exit(EXIT_PANIC)
    assert "TEST divzero: PASS" not in emulator.transcript
    # The firmware has no frame pointers: the back trace is the return
    # addresses found on the stack (boot/src/Panic.cpp). Each must be code
    # that follows a call, and together they must name the way the fault
    # came: through the interrupt entry, from the test runner the shell
    # called, down from the console task's entry.
    names = symbolize(isa486.image("test"), trace)
    assert len(names) == len(trace), f"addresses outside the code in {[hex(a) for a in trace]}: {names}"
    functions = " | ".join(names[address] for address in trace)
    for caller in (r"interruptEntry|interrupt_common", r"runTargetTest", r"Shell::execute", r"taskEntryTrampoline"):
        assert re.search(caller, functions), f"{caller} missing from the back trace: {functions}"
