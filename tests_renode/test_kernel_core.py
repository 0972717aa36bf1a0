"""The kernel core on the emulated 486 board: tasks, scheduling, timers, ids and recovery.

Each case boots the test image under -icount, where the emulator's clock
follows retired instructions, so every timing the on-target test checks is
exact and repeatable however busy this machine is. The on-target tests live
in tests_renode/target/ and print what they measured; a failure shows it in
the console transcript.
"""

import pytest

from dcoslab.board import EXIT_PASS

KERNEL_TESTS = [
    "preempt",      # a task readied in a nested ISR runs at the outermost exit
    "roundrobin",   # Yield among equal priorities
    "timeslice",    # time-sliced tasks alternate; plain ones do not
    "priority",     # ChangePriority
    "deadline",     # deadline ordering with every tie-break, before static tasks
    "deadlinemiss", # a missed deadline raises a timing exception within a tick
    "events",       # all, any, time-out, poll, not queued
    "signals",      # priority order, no nesting, masking
    "suspend",      # Suspend and Resume
    "exceptions",   # divide error caught by a handler; unguarded task ends; thrown exception
    "alarms",       # watchdog, periodic, day-clock alarms; by event and by signal
    "sleep",        # SleepFor, SleepTill
    "recovery",     # KillTask and Delete recover timers, devices, stack, slot
    "fulltable",    # TableFull, AddObjects, argument errors
    "forgedid",     # forged, foreign, mistyped, null and stale ids
    "isrblock",     # blocking services refused in ISRs
    "intlevel",     # SetInterruptLevel and the legal limit
    "profiling",    # StartProfiling/StopProfiling/GetTimingInfo exclude preemption
    "fpu",          # FPU context per floating-point task
]


@pytest.mark.parametrize("name", KERNEL_TESTS)
def test_kernel(boot, isa486, name):
    emulator = boot(isa486, "test", icount=True)
    emulator.expect(r"dcos> ")
    emulator.send(f"test {name} --exit\r")
    emulator.expect(rf"TEST {name}: (PASS|FAIL)", timeout=120)
    emulator.expect_exit(EXIT_PASS, timeout=120)


def test_every_kernel_target_test_is_run(boot, isa486):
    """The list above and the image agree, so no on-target test is forgotten."""
    emulator = boot(isa486, "test")
    emulator.expect(r"dcos> ")
    listed = emulator.command("test list")
    names = {line.split()[0] for line in listed.splitlines() if line.strip()}
    board_tests = {"tick", "irqmask", "divzero", "txflood"}
    assert names - board_tests == set(KERNEL_TESTS)


def test_unguarded_task_exception_is_reported_and_the_node_survives(boot, isa486):
    emulator = boot(isa486, "test", icount=True)
    emulator.expect(r"dcos> ")
    emulator.send("test exceptions\r")
    emulator.expect(r"task unguarded \(0x[0-9a-f]{8}\) terminated: synchronous exception, vector 0 "
                    r"\(#DE divide error\) at EIP=[0-9a-f]{8}")
    emulator.expect(r"TEST exceptions: PASS")
    emulator.expect(r"dcos> ")
    tasks = emulator.command("tasks")
    assert "unguarded" not in tasks
    assert "shell" in tasks and "idle" in tasks
