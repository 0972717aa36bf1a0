"""The benchmark framework on the bench image: command format and exact counting.

These tests check that the framework works, not how fast anything is: under
-icount the time-stamp counter counts retired instructions, so an O(1)
primitive must report the same count for 8 and for 4096 objects, and the
same count on every call. No test here asserts a speed target.
"""

import os
import re
import sys

import pytest

from dcoslab.emulator import Emulator

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "bench"))

from run_benchmarks import LIST_LINE, parse_run  # noqa: E402

PROMPT = r"dcos> "


@pytest.fixture
def boot_bench(request, isa486):
    """Starts the bench image, on the board's benchmark CPU unless cpu says otherwise."""
    started = request.node.__dict__.setdefault("dcos_emulators", [])

    def start(cpu=isa486.benchmark_cpu, icount=True):
        emulator = Emulator(isa486, isa486.image("benchmark"), icount=icount, cpu=cpu)
        started.append(emulator)
        emulator.start()
        emulator.expect(PROMPT)
        return emulator

    yield start
    for emulator in started:
        emulator.close()


def test_bench_list_names_every_benchmark_in_the_fixed_format(boot_bench):
    output = boot_bench().command("bench list")
    lines = [line for line in output.splitlines() if line]
    assert lines[-1] == "BENCH done"
    entries = [LIST_LINE.fullmatch(line) for line in lines[:-1]]
    assert all(entries), output
    names = [entry["name"] for entry in entries]
    assert all(re.fullmatch(r"[A-Z][A-Za-z]*\.[A-Z][A-Za-z0-9]*", name) for name in names), names
    assert len(names) == len(set(names)), "benchmark names must be unique"
    assert "Kernel.ResolveId" in names


def test_resolve_id_costs_the_same_instructions_for_8_and_4096_objects(boot_bench):
    output = boot_bench().command("bench run Kernel.ResolveId")
    assert output.splitlines()[-1] == "BENCH done", output
    overhead, results = parse_run(output)
    assert overhead["min"] == overhead["max"], "under -icount the empty measurement must cost the same every time"
    assert list(results) == ["Kernel.ResolveId"], output
    entry = results["Kernel.ResolveId"]
    assert entry["cost"] == "constant" and entry["variable"] is False
    (min_8, max_8), (min_4096, max_4096) = entry[8], entry[4096]
    assert min_8 > 0, "a resolve retires at least one instruction beyond an empty call"
    assert min_8 == max_8 and min_4096 == max_4096, "exact counting: every call of an O(1) path counts the same"
    assert min_8 == min_4096, "ObjectTable::resolve must not depend on the number of objects"


def test_bench_refuses_to_run_without_a_time_stamp_counter(boot_bench, isa486):
    # The board's own CPU is an i486, which has no RDTSC: the command must say
    # so instead of taking an invalid-opcode exception.
    output = boot_bench(cpu=isa486.cpu, icount=False).command("bench run Kernel.ResolveId")
    assert "BENCH error no time-stamp counter" in output


def test_agent_benchmarks_are_registered_under_the_seed_names(boot_bench):
    output = boot_bench().command("bench list")
    names = {entry["name"] for entry in LIST_LINE.finditer(output)}
    for name in ("Kernel.ContextSwitch", "Kernel.InterruptLatency", "Kernel.StaticScheduling",
                 "Kernel.DynamicScheduling", "Kernel.FloatingPointContext", "Task.Create", "Task.PostEvent",
                 "Task.PendOnEvents", "Scheduler.Yield", "Scheduler.SetDeadline", "Timer.SetWatchDogAlarm",
                 "Timer.CancelAlarm", "System.Open", "System.InstallISR"):
        assert name in names, f"{name} is missing from 'bench list':\n{output}"


def test_self_timed_switch_benchmarks_report_exact_flat_counts_with_4096_tasks(boot_bench):
    # Self-timed benchmarks (the interval runs from one task into another, or
    # into an interrupt handler) must mark an interval for both object
    # counts, including the 4096-task population the bench image's larger
    # tables allow. Only the design's O(1) claim is checked, not a speed.
    output = boot_bench().command("bench run Kernel", timeout=120)
    assert output.splitlines()[-1] == "BENCH done", output
    assert " error=" not in output, output
    _, results = parse_run(output)
    for name in ("Kernel.ContextSwitch", "Kernel.InterruptLatency", "Kernel.StaticScheduling"):
        entry = results[name]
        assert entry["cost"] == "constant"
        (min_8, _), (min_4096, _) = entry[8], entry[4096]
        assert min_8 > 0, f"{name}: an interval was marked"
        assert min_8 == min_4096, f"{name} must not depend on the number of tasks: {min_8} vs {min_4096}"
    assert results["Kernel.DynamicScheduling"]["cost"] == "log"
