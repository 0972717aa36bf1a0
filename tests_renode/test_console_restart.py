"""The console outlives a fault in the shell (Kernel.cpp's root task).

The root task starts the console shell and starts it again when it ends, up
to a limit; the application and every other task carry on meanwhile.
"""

import re

CONSOLE_TARGET_TESTS = [
    "shellfault",  # a #GP in the shell task itself; checked here by what the console does next
]

FAULT = (r"task shell \(0x[0-9a-f]{8}\) terminated: fatal exception, vector 13 \(#GP general protection[^)]*\) "
         r"at EIP=[0-9a-f]{8}")


def test_a_fatal_exception_in_the_shell_gives_a_new_shell(boot, isa486):
    emulator = boot(isa486, "test", icount=True)
    emulator.expect(r"dcos> ")
    before = emulator.command("tasks")
    emulator.send("test shellfault\r")
    emulator.expect(FAULT)
    emulator.expect(r"console: the shell ended; starting it again\r\n")
    emulator.expect(r"dcos> ")
    assert "the shell was not stopped" not in emulator.transcript
    # A working console, with a new shell task next to the root task.
    assert "DCOS" in emulator.command("version")
    after = emulator.command("tasks")
    old_shell = re.search(r"([0-9a-f]{8}) +shell", before)
    new_shell = re.search(r"([0-9a-f]{8}) +shell", after)
    assert old_shell and new_shell, after
    assert old_shell.group(1) != new_shell.group(1)
    assert "console" in after


def test_the_console_stops_restarting_a_shell_that_keeps_ending(boot, isa486):
    emulator = boot(isa486, "test", icount=True)
    for _ in range(7):
        emulator.expect(r"dcos> ")
        emulator.send("test shellfault\r")
        emulator.expect(r"console: the shell ended; starting it again")
    emulator.expect(r"dcos> ")
    emulator.send("test shellfault\r")
    emulator.expect(FAULT)
    emulator.expect(r"console: the shell ended 8 times; not starting it again")
