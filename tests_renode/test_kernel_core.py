"""The kernel core on the emulated 486 board: tasks, scheduling, timers, ids and recovery.

Each case boots the test image under -icount, where the emulator's clock
follows retired instructions, so every timing the on-target test checks is
exact and repeatable however busy this machine is. The on-target tests live
in tests_renode/target/ and print what they measured; a failure shows it in
the console transcript.
"""

import importlib.util
import os

import pytest

from dcoslab.target import run_target_test

KERNEL_TARGET_TESTS = [
    "preempt",      # a task readied in a nested ISR runs at the outermost exit
    "roundrobin",   # Yield among equal priorities
    "yieldcases",   # Yield to a partner preempted at a tick, and to one with a signal pending
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
    "oddids",       # the null and all-ones ids on every agent's fast path
    "isrblock",     # blocking services refused in ISRs
    "intlevel",     # SetInterruptLevel and the legal limit
    "profiling",    # StartProfiling/StopProfiling/GetTimingInfo exclude preemption
    "fpu",          # FPU context per floating-point task
    "recoverall",   # a dying task gives back a buffer, a segment, a semaphore and a port
]


@pytest.mark.parametrize("name", KERNEL_TARGET_TESTS)
def test_kernel(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)


def test_every_target_test_is_run(boot, isa486):
    """Every on-target test in the image is run by some emulator test.

    Each test module that runs on-target tests names them in a module-level
    list whose name ends in _TARGET_TESTS; together they must cover the image.
    """
    emulator = boot(isa486, "test")
    emulator.expect(r"dcos> ")
    listed = emulator.command("test list")
    in_image = {line.split()[0] for line in listed.splitlines() if line.strip()}
    covered = set()
    directory = os.path.dirname(os.path.abspath(__file__))
    for filename in sorted(os.listdir(directory)):
        if filename.startswith("test_") and filename.endswith(".py"):
            spec = importlib.util.spec_from_file_location(filename[:-3], os.path.join(directory, filename))
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            for name, value in vars(module).items():
                if name.endswith("_TARGET_TESTS"):
                    covered.update(value)
    assert in_image - covered == set(), "on-target tests no emulator test runs"
    assert covered - in_image == set(), "emulator tests name on-target tests the image lacks"


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
