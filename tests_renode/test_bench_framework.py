"""The benchmark framework on the bench image: command format and exact counting.

These tests check that the framework works, not how fast anything is: under
-icount the time-stamp counter counts retired instructions, so an O(1)
primitive must report the same count for 8 and for 4096 objects, and the
same count on every call. No test here asserts a speed target.
"""

import os
import re
import subprocess
import sys

import pytest

from dcoslab.emulator import Emulator

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "bench"))

from run_benchmarks import (CAN_RECEIVE_PIECES, CAN_SEND_PIECES, LIST_LINE, MODBUS_CHARACTER_PIECES,  # noqa: E402
                            MODBUS_REQUESTS, can_summary, modbus_summary, parse_run)
from seed_figures import SEED_FIGURES  # noqa: E402

PROMPT = r"dcos> "


@pytest.fixture
def boot_bench(request, isa486):
    """Starts the bench image, on the board's benchmark CPU unless cpu says otherwise."""
    started = request.node.__dict__.setdefault("dcos_emulators", [])

    def start(cpu=isa486.benchmark_cpu, icount=True):
        emulator = Emulator(isa486, isa486.image("benchmark"), icount=icount, cpu=cpu,
                            memory_mib=isa486.benchmark_memory())
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


# Every primitive of the seed's Tables 9.6 to 9.10 that DCOS has, under the
# seed's names (the seed's GetUsageInfo is GetStatistics), and the extra
# figures: the waiting forms of the blocking primitives and first fit over
# a fragmented free list.
AGENT_BENCHMARKS = {
    "BufferPool": ("NameToObject", "AddObjects", "XferOwnership", "Create", "Delete", "Allocate", "Return",
                   "GetUsageInfo"),
    "Heap": ("NameToObject", "AddObjects", "XferOwnership", "Create", "Delete", "Allocate", "Return", "GetUsageInfo",
             "AllocateFragmented", "GetUsageInfoFragmented"),
    "Dsm": ("NameToObject", "AddSubscribers", "AddObjects", "XferOwnership", "Create", "Delete", "Open", "Close",
            "Read", "Write", "ReadWaiting"),
    "Port": ("NameToObject", "AddObjects", "XferOwnership", "Create", "Delete", "Send", "Receive", "AddMsgBufs",
             "ReceiveWaiting"),
    "Semaphore": ("NameToObject", "AddObjects", "XferOwnership", "Create", "Delete", "Acquire", "Release",
                  "AcquireWaiting"),
}


def test_every_primitive_of_the_memory_communication_and_synchronisation_agents_is_benchmarked(boot_bench):
    output = boot_bench().command("bench list")
    names = {entry["name"] for entry in LIST_LINE.finditer(output)}
    for agent, primitives in AGENT_BENCHMARKS.items():
        for primitive in primitives:
            assert f"{agent}.{primitive}" in names, f"{agent}.{primitive} is missing from 'bench list':\n{output}"
        seed_names = {name for name in SEED_FIGURES if name.split(".", 1)[0] == agent}
        assert seed_names <= names, f"seed primitives of {agent} without a benchmark: {sorted(seed_names - names)}"


def test_agent_benchmarks_report_exact_counts_for_8_and_4096_objects(boot_bench):
    # Checks the method, not a speed: every benchmark of the five agents
    # reports figures for both object counts (AddObjects and AddSubscribers
    # are refused with 4096 objects: the table is full by definition), and
    # under exact counting a fixed-cost path run with interrupts disabled
    # costs the same on every call, so min == max == median.
    emulator = boot_bench()
    irq = {entry["name"]: entry["irq"] == "on" for entry in LIST_LINE.finditer(emulator.command("bench list"))}
    for agent in AGENT_BENCHMARKS:
        output = emulator.command(f"bench run {agent}", timeout=180)
        assert output.splitlines()[-1] == "BENCH done", output
        _, results = parse_run(output)
        assert set(results) == {f"{agent}.{primitive}" for primitive in AGENT_BENCHMARKS[agent]}, output
        for name, entry in results.items():
            for objects in (8, 4096):
                if objects == 4096 and name.endswith((".AddObjects", ".AddSubscribers")):
                    assert entry[objects] == "setup failed: object table full", f"{name}: {entry[objects]}"
                    continue
                assert isinstance(entry[objects], tuple), f"{name} with {objects} objects: {entry[objects]}"
                low, high = entry[objects]
                assert low > 0, f"{name} with {objects} objects: nothing was measured"
                if entry["cost"] == "constant" and not irq[name]:
                    assert low == high == entry["median"][objects], (
                        f"{name} with {objects} objects: an O(1) path must count the same on every call: {entry}")


def test_can_frame_benchmarks_move_real_frames_through_the_chip_with_exact_counts(boot_bench):
    # Each CAN piece's setup and restore pass a frame through the card's chip
    # (self test, self reception) and fail when the chip does not deliver
    # (setup failed), and each measured call fails when it finds no frame
    # (measured call failed): a figure means a frame was handled. The
    # routines run with interrupts disabled on a fixed path, so the count
    # is the same on every call.
    emulator = boot_bench()
    output = emulator.command("bench run Can", timeout=180)
    assert output.splitlines()[-1] == "BENCH done", output
    _, results = parse_run(output)
    assert set(results) == set(CAN_RECEIVE_PIECES + CAN_SEND_PIECES), output
    for name, entry in results.items():
        for objects in (8, 4096):
            assert isinstance(entry[objects], tuple), f"{name} with {objects} objects: {entry[objects]}"
            low, high = entry[objects]
            assert 0 < low == high == entry["median"][objects], f"{name}: {entry}"
    summary = can_summary(results)
    assert summary["received"]["instructions_per_frame"] == sum(results[name][8][0] for name in CAN_RECEIVE_PIECES)
    assert summary["sent"]["instructions_per_second"] == 7407 * sum(results[name][8][0] for name in CAN_SEND_PIECES)


def test_modbus_line_benchmarks_handle_real_characters_and_requests_with_exact_counts(boot_bench):
    # The receive interrupt's character comes through COM2's 16550 (loopback)
    # and each request's response is checked (address, function, byte count,
    # the registers read or the write's echo, CRC) in the unmeasured restore
    # step, which fails the benchmark otherwise (measured call failed): a
    # figure means a character was queued or a request answered. The paths
    # run with interrupts disabled on fixed data and the line's own times, so
    # every call counts the same.
    output = boot_bench().command("bench run Modbus", timeout=180)
    assert output.splitlines()[-1] == "BENCH done", output
    _, results = parse_run(output)
    assert set(results) == set(MODBUS_CHARACTER_PIECES) | set(MODBUS_REQUESTS), output
    for name, entry in results.items():
        for objects in (8, 4096):
            assert isinstance(entry[objects], tuple), f"{name} with {objects} objects: {entry[objects]}"
            low, high = entry[objects]
            assert 0 < low == high == entry["median"][objects], f"{name}: {entry}"
    summary = modbus_summary(results)
    per_character = sum(results[name][8][0] for name in MODBUS_CHARACTER_PIECES)
    assert summary["instructions_per_character"] == per_character
    read = summary["requests"]["Modbus.ReadHoldingRegisters"]
    assert read["instructions_per_transaction"] == 8 * per_character + results["Modbus.ReadHoldingRegisters"][8][0]
    # [SL] 2.5.1.1 at 115200 baud: 8 + 25 characters of 11 bits and two t3.5 of 1.75 ms.
    assert read["line_limit_transactions_per_second"] == pytest.approx(1 / (33 * 11 / 115200 + 2 * 1.75e-3))
    write = summary["requests"]["Modbus.WriteMultipleRegisters"]
    assert write["line_limit_transactions_per_second"] == pytest.approx(1 / (37 * 11 / 115200 + 2 * 1.75e-3))
    assert read["share_of_emulated_cpu"] == pytest.approx(
        read["instructions_per_transaction"] * read["line_limit_transactions_per_second"] / 1e9)


def test_the_instruction_trace_of_a_benchmark_accounts_for_its_figure_exactly():
    """trace_primitive.py's trace of one call is the bench's figure plus the
    empty function's ret that the bench subtracts, and names the functions."""
    tool = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bench", "trace_primitive.py")
    result = subprocess.run([sys.executable, tool, "Semaphore.Acquire"], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    traced = re.search(r"^Semaphore.Acquire: (\d+) instructions from acquire\(\)", result.stdout, re.MULTILINE)
    figure = re.search(r"^bench figure: (\d+)", result.stdout, re.MULTILINE)
    assert traced and figure, result.stdout
    assert int(traced.group(1)) == int(figure.group(1)) + 1, result.stdout
    assert re.search(r"^\s+\d+\s+dcos::SemaphoreAgent::Acquire\(", result.stdout, re.MULTILINE), result.stdout
