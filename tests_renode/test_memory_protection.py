"""A task's fault stays the task's: stack guards, null pointers, kernel tasks.

Paging gives every task stack a guard page and leaves page 0 out; page
faults are taken by a fault task with a stack of its own, so even a task
with no stack left is reported and ended while the node carries on. Each
on-target test runs the faulting task beside a neighbour whose stack lies
just below it, where an overflow used to land, and checks the neighbour
runs on and every stack comes back. These cases check the report an
engineer reads on the console as well.
"""

import pytest

MEMORY_PROTECTION_TARGET_TESTS = [
    "overflowlocal",  # a 6,000-byte local in a 2 KiB stack
    "overflowdeep",   # unbounded recursion, well past the stack area
    "overflowirq",    # an interrupt's frame pushed into the guard page; the tick goes on
    "nullwrite",      # a write through a null pointer
    "nullread",       # a read at a small offset from a null pointer
    "kerneltasks",    # idle and console cannot be killed or suspended by an ordinary task
    "stackmark",      # the stack high-water mark
]

ID = r"0x[0-9a-f]{8}"
HEX = r"[0-9a-f]{8}"

REPORTS = {
    "overflowlocal": [rf"task largelocal \({ID}\) terminated: fatal exception, vector 14 \(#PF page fault\) "
                      rf"at EIP={HEX}",
                      rf"  stack overflow: the stack of 4096 bytes at {HEX}-{HEX} ran into its guard page "
                      rf"\((read|write) at {HEX}, ESP={HEX}\)"],
    "overflowdeep": [rf"task recursion \({ID}\) terminated: fatal exception, vector 14",
                     rf"  stack overflow: the stack of 8192 bytes at {HEX}-{HEX} ran into its guard page"],
    "overflowirq": [rf"task irqoverflow \({ID}\) terminated: fatal exception, vector 14",
                    rf"  stack overflow: the stack of 4096 bytes at {HEX}-{HEX} ran into its guard page "
                    rf"\(write at {HEX}"],
    "nullwrite": [rf"task nullwrite \({ID}\) terminated: fatal exception, vector 14",
                  r"  null pointer: write at 00000000"],
    "nullread": [rf"task nullread \({ID}\) terminated: fatal exception, vector 14",
                 r"  null pointer: read at 00000008"],
}


@pytest.mark.parametrize("name", MEMORY_PROTECTION_TARGET_TESTS)
def test_memory_protection(boot, isa486, name):
    emulator = boot(isa486, "test", icount=True)
    emulator.expect(r"dcos> ")
    emulator.send(f"test {name}\r")
    for pattern in REPORTS.get(name, []):
        emulator.expect(pattern)
    emulator.expect(rf"TEST {name}: PASS")
    emulator.expect(r"dcos> ")
    # The console is unharmed: it still answers and lists the kernel's tasks.
    tasks = emulator.command("tasks")
    for kernel_task in ("idle", "console", "shell"):
        assert kernel_task in tasks


def test_every_fault_in_one_boot_leaves_the_node_whole(boot, isa486):
    """All faults one after another: the arena and the console stay whole."""
    emulator = boot(isa486, "test", icount=True)
    emulator.expect(r"dcos> ")
    before = emulator.command("tasks")
    for name in MEMORY_PROTECTION_TARGET_TESTS:
        emulator.send(f"test {name}\r")
        emulator.expect(rf"TEST {name}: PASS")
        emulator.expect(r"dcos> ")
    after = emulator.command("tasks")
    free = lambda listing: listing.strip().splitlines()[-1].split("stack arena")[1]
    assert free(before) == free(after), "the stack arena is as it was"


def test_tasks_shows_stack_use(boot, isa486):
    emulator = boot(isa486, "production")
    emulator.expect(r"dcos> ")
    listing = emulator.command("tasks")
    assert "used" in listing
    for line in listing.splitlines():
        fields = line.split()
        if len(fields) >= 6 and fields[1] in ("idle", "console", "shell"):
            size, used = int(fields[4]), int(fields[5])
            assert 0 < used < size, line


def test_mem_reports_the_page_tables(boot, isa486):
    emulator = boot(isa486, "production")
    emulator.expect(r"dcos> ")
    listing = emulator.command("mem")
    assert "page 0 and stack guards not present" in listing
