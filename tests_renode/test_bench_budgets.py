"""The budget checks of `make bench` (tests_renode/bench/budgets.py, footprint.py).

Pure Python on small fixtures: no emulator is booted, so these run in a
second. They check the comparison logic that `make bench STRICT=1` relies on
(over budget fails, within passes, a flat mismatch fails, a missing figure
is reported, a budget not measured yet is never an offender), the footprint
report's reading of a linker map, and that budgets.toml holds the issue's
budgets under names the benchmarks really register. They never check how
fast anything is: that is `make bench`'s report.
"""

import json
import os
import re
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
BENCH = os.path.join(HERE, "bench")
sys.path.insert(0, BENCH)
sys.path.insert(0, os.path.join(HERE, "thread_metric"))

import budgets  # noqa: E402
import footprint  # noqa: E402
import remote_bench  # noqa: E402
import run_thread_metric  # noqa: E402

BUDGETS_PY = os.path.join(BENCH, "budgets.py")


def small_budgets(**primitives):
    """A parsed budget file with the given primitives and one Thread-Metric and one footprint budget."""
    return budgets.parse_budgets({
        "primitives": primitives,
        "thread_metric": {"synchronization_processing": {"freertos": 133, "budget": 66.5}},
        "footprint": {"full": {"image": "build/486/dcos486.elf", "kernel": ["firmware/dcos/"], "text_budget": 1000},
                      "minimal": {"text_budget": 100, "measured": False}},
    }, "fixture")


def entry(small, large, cost="constant"):
    """A primitives.json entry with those instruction figures."""
    return {"instructions_8": small, "instructions_4096": large, "variable": cost == "variable", "cost": cost}


def verdict_of(rows, name):
    return next(row for row in rows if row["name"] == name)


def test_a_figure_within_its_budget_passes_and_one_over_it_is_an_offender():
    fixture = small_budgets(**{"Semaphore.Acquire": {"budget": 30, "flat": True},
                               "Semaphore.Release": {"budget": 35, "flat": True}})
    rows = budgets.check_primitives(fixture, {"Semaphore.Acquire": entry(30, 30),
                                              "Semaphore.Release": entry(36, 36)})
    assert verdict_of(rows, "Semaphore.Acquire")["verdict"] == budgets.WITHIN
    assert verdict_of(rows, "Semaphore.Acquire")["offences"] == []
    assert verdict_of(rows, "Semaphore.Release")["verdict"] == budgets.OVER
    assert budgets.offenders(rows) == ["Semaphore.Release: 36 instructions, over its budget of 35"]


def test_the_larger_of_the_two_object_counts_is_held_against_the_budget():
    fixture = small_budgets(**{"Heap.AllocateFragmented": {"budget": 200}})
    rows = budgets.check_primitives(fixture, {"Heap.AllocateFragmented": entry(150, 627571, "variable")})
    assert rows[0]["verdict"] == budgets.OVER
    assert "627571" in rows[0]["offences"][0]


def test_a_flat_budget_fails_when_8_and_4096_objects_differ_even_by_one():
    fixture = small_budgets(**{"Timer.Create": {"flat": True}, "Port.Send": {"budget": 60, "flat": True}})
    rows = budgets.check_primitives(fixture, {"Timer.Create": entry(179, 180), "Port.Send": entry(50, 50)})
    create = verdict_of(rows, "Timer.Create")
    assert create["verdict"] == budgets.NO_COUNT and create["flat_agrees"] is False
    assert create["offences"] == ["Timer.Create: 179 with 8 objects, 180 with 4096: must be flat"]
    assert verdict_of(rows, "Port.Send")["flat_agrees"] is True
    assert verdict_of(rows, "Port.Send")["offences"] == []


def test_a_fixed_cost_benchmark_must_be_flat_even_where_its_budget_does_not_ask():
    fixture = small_budgets(**{"Dsm.Open": {"budget": 300}})
    rows = budgets.check_primitives(fixture, {"Dsm.Open": entry(207, 209)})
    assert rows[0]["verdict"] == budgets.WITHIN and rows[0]["flat_agrees"] is False
    assert rows[0]["offences"] == ["Dsm.Open: 207 with 8 objects, 209 with 4096: must be flat"]


def test_an_unbudgeted_fixed_cost_benchmark_that_is_not_flat_is_an_offender_and_a_variable_one_is_not():
    fixture = small_budgets()
    rows = budgets.check_primitives(fixture, {"Dsm.Close": entry(125, 124), "Dsm.Read": entry(160, 160),
                                              "Task.Create": entry(642, 643, "variable"),
                                              "Kernel.DynamicScheduling": entry(574, 808, "log")})
    assert [row["name"] for row in rows] == ["Dsm.Close"]
    assert budgets.offenders(rows) == ["Dsm.Close: 125 with 8 objects, 124 with 4096: declared O(1) but NOT FLAT"]


def test_a_missing_figure_is_reported_as_an_offender():
    fixture = small_budgets(**{"Kernel.ContextSwitch": {"budget": 20, "flat": True},
                               "System.AddObjects": {"budget": 300}})
    rows = budgets.check_primitives(fixture, {"System.AddObjects": entry(220, None, "variable")})
    switch = verdict_of(rows, "Kernel.ContextSwitch")
    assert switch["verdict"] == budgets.MISSING
    assert switch["offences"] == ["Kernel.ContextSwitch: no figure (no benchmark of that name ran)"]
    add = verdict_of(rows, "System.AddObjects")
    assert add["verdict"] == budgets.MISSING
    assert add["offences"] == ["System.AddObjects: no figure with 4096 objects"]


def test_a_budget_not_measured_yet_is_reported_but_never_an_offender():
    fixture = small_budgets(**{"Kernel.DynamicScheduling64": {"budget": 250, "measured": False}})
    rows = budgets.check_primitives(fixture, {})
    assert rows[0]["verdict"] == budgets.NOT_MEASURED_YET and rows[0]["offences"] == []
    assert rows[0]["instructions_8"] is None and rows[0]["instructions_4096"] is None
    lines = budgets.primitive_lines(rows, budgets.DEFAULT_BUDGETS)
    assert any("Kernel.DynamicScheduling64: not measured yet" in line for line in lines)
    # Once a benchmark of that name exists, its figure is checked after all.
    rows = budgets.check_primitives(fixture, {"Kernel.DynamicScheduling64": entry(300, 300, "log")})
    assert rows[0]["verdict"] == budgets.OVER


def test_a_selection_leaves_out_the_budgets_of_benchmarks_that_did_not_run():
    fixture = small_budgets(**{"Kernel.ContextSwitch": {"budget": 20}, "Port.Send": {"budget": 60}})
    rows = budgets.check_primitives(fixture, {"Port.Send": entry(50, 50)}, selection="Port")
    assert [row["name"] for row in rows] == ["Port.Send"]


def test_thread_metric_figures_are_held_against_half_of_freertos():
    fixture = small_budgets()
    within = budgets.check_thread_metric(fixture, {"synchronization_processing": {"instructions_per_iteration": 66.5}})
    assert within[0]["verdict"] == budgets.WITHIN and within[0]["offences"] == []
    over = budgets.check_thread_metric(fixture, {"synchronization_processing": {"instructions_per_iteration": 66.6}})
    assert over[0]["verdict"] == budgets.OVER and len(over[0]["offences"]) == 1
    # The exact quotient decides, not the figure rounded to two decimals.
    edge = budgets.check_thread_metric(fixture, {"synchronization_processing": {
        "iterations": 2000, "instructions": 133001, "instructions_per_iteration": 66.5}})
    assert edge[0]["verdict"] == budgets.OVER
    missing = budgets.check_thread_metric(fixture, {})
    assert missing[0]["verdict"] == budgets.MISSING and missing[0]["offences"]


def test_the_footprint_budget_fails_over_and_a_configuration_not_built_yet_is_not_an_offender():
    fixture = small_budgets()
    rows = budgets.check_footprint(fixture, {"full": 1001})
    assert verdict_of(rows, "full")["verdict"] == budgets.OVER
    assert verdict_of(rows, "minimal")["verdict"] == budgets.NOT_MEASURED_YET
    assert budgets.offenders(rows) == ["footprint full: kernel code 1001 bytes, over its budget of 1000 bytes"]
    assert budgets.offenders(budgets.check_footprint(fixture, {"full": 1000})) == []


def test_the_budget_file_refuses_unknown_keys_and_entries_that_set_nothing():
    with pytest.raises(budgets.BudgetFileError, match="unknown keys"):
        budgets.parse_budgets({"primitives": {"Port.Send": {"budjet": 60}}})
    with pytest.raises(budgets.BudgetFileError, match="neither"):
        budgets.parse_budgets({"primitives": {"Port.Send": {"note": "nothing to check"}}})
    with pytest.raises(budgets.BudgetFileError, match="no budget"):
        budgets.parse_budgets({"thread_metric": {"message_processing": {"freertos": 236}}})


def remote_entry(**figures):
    """A remote.json primitive whose instruction figures are (min, max) pairs."""
    return {"instructions": {figure: {"min": low, "median": low, "max": high}
                             for figure, (low, high) in figures.items()}}


def test_remote_counts_must_be_there_positive_identical_and_within_a_budget_where_one_is_set():
    fixture = budgets.parse_budgets({"remote": {
        "SemaphoreRelease": {"figures": ["caller_request", "callee"], "identical": True, "now": {"callee": 4070},
                             "bound": "the same count on every call"},
        "PostEvent": {"figures": ["callee"], "budget": {"callee": 4000}},
        "MessagePortSend": {"figures": ["callee"], "identical": True, "measured": False}}})
    rows = budgets.check_remote(fixture, {
        "SemaphoreRelease": remote_entry(caller_request=(1881, 1881), callee=(4070, 4073)),
        "PostEvent": remote_entry(callee=(4096, 4096))})
    by_figure = {(row["primitive"], row["figure"]): row for row in rows}
    request = by_figure["SemaphoreRelease", "caller_request"]
    assert request["verdict"] == budgets.NO_COUNT and request["identical_agrees"] and request["offences"] == []
    callee = by_figure["SemaphoreRelease", "callee"]
    assert callee["identical_agrees"] is False and callee["now"] == 4070
    assert callee["offences"] == ["remote SemaphoreRelease callee: 4070 to 4073 instructions: every call must count "
                                  "the same"]
    post = by_figure["PostEvent", "callee"]
    assert post["verdict"] == budgets.OVER and post["identical_agrees"] is None
    assert post["offences"] == ["remote PostEvent callee: 4096 instructions, over its budget of 4000"]
    port = by_figure["MessagePortSend", "callee"]
    assert port["verdict"] == budgets.NOT_MEASURED_YET and port["offences"] == []
    assert "1 not identical; 2 offenders" in budgets.summary_text(rows)
    # An image without the counter reports zeros, and a report without the figure is missing.
    rows = budgets.check_remote(fixture, {"SemaphoreRelease": remote_entry(caller_request=(0, 0))})
    assert any("0 instructions: not counted" in offence for offence in budgets.offenders(rows))
    assert any("callee: no figure" in offence for offence in budgets.offenders(rows))
    lines = budgets.remote_lines(budgets.check_remote(fixture, {}), budgets.DEFAULT_BUDGETS)
    assert any("SemaphoreRelease: bound: the same count on every call" in line for line in lines)


def test_the_budget_file_refuses_remote_entries_it_could_not_check():
    with pytest.raises(budgets.BudgetFileError, match="names no figures"):
        budgets.parse_budgets({"remote": {"PostEvent": {"identical": True}}})
    with pytest.raises(budgets.BudgetFileError, match="unknown figure"):
        budgets.parse_budgets({"remote": {"PostEvent": {"figures": ["calee"], "identical": True}}})
    with pytest.raises(budgets.BudgetFileError, match="not among its figures"):
        budgets.parse_budgets({"remote": {"PostEvent": {"figures": ["callee"], "budget": {"caller_reply": 1}}}})
    with pytest.raises(budgets.BudgetFileError, match="neither"):
        budgets.parse_budgets({"remote": {"PostEvent": {"figures": ["callee"]}}})
    with pytest.raises(budgets.BudgetFileError, match="unknown keys"):
        budgets.parse_budgets({"remote": {"PostEvent": {"figures": ["callee"], "flat": True}}})


def run_verdict(tmp_path, primitives, strict):
    """Runs budgets.py as `make bench` does, on fixture reports; returns the process and budgets.json."""
    budget_file = tmp_path / "budgets.toml"
    budget_file.write_text('[primitives."Port.Send"]\nbudget = 60\nflat = true\n'
                           '[primitives."Kernel.DynamicScheduling64"]\nbudget = 250\nmeasured = false\n'
                           "[thread_metric.message_processing]\nfreertos = 236\nbudget = 118\n"
                           '[footprint.full]\nimage = "build/486/dcos486.elf"\ntext_budget = 1000\n'
                           "[footprint.minimal]\ntext_budget = 100\nmeasured = false\n")
    (tmp_path / "primitives.json").write_text(json.dumps(primitives))
    (tmp_path / "thread_metric.json").write_text(json.dumps(
        {"message_processing": {"instructions_per_iteration": 100.0}}))
    (tmp_path / "footprint.json").write_text(json.dumps(
        {"images": {"full": {"kernel": {"text": 900, "rodata": 0, "data": 0, "bss": 0}}}}))
    command = [sys.executable, BUDGETS_PY, "--budgets", str(budget_file), "--output", str(tmp_path / "out.json")]
    for name in ("primitives", "thread_metric", "footprint"):
        command += [f"--{name.replace('_', '-')}", str(tmp_path / f"{name}.json")]
    process = subprocess.run(command + (["--strict"] if strict else []), capture_output=True, text=True, timeout=60)
    return process, json.loads((tmp_path / "out.json").read_text())


def test_strict_mode_exits_non_zero_listing_every_offender(tmp_path):
    process, report = run_verdict(tmp_path, {"Port.Send": entry(61, 61), "Dsm.Close": entry(125, 124)}, strict=True)
    assert process.returncode == 1, process.stdout + process.stderr
    assert "Port.Send: 61 instructions, over its budget of 60" in process.stderr
    assert "Dsm.Close: 125 with 8 objects, 124 with 4096: declared O(1) but NOT FLAT" in process.stderr
    assert report["strict"] is True and len(report["offenders"]) == 2
    assert report["not_measured_yet"] == ["Kernel.DynamicScheduling64", "minimal"]


def test_strict_mode_passes_when_every_figure_is_within_its_budget(tmp_path):
    process, report = run_verdict(tmp_path, {"Port.Send": entry(60, 60), "Dsm.Close": entry(125, 125)}, strict=True)
    assert process.returncode == 0, process.stdout + process.stderr
    assert report["offenders"] == []
    assert "not measured yet" in process.stdout


def test_without_strict_offenders_are_reported_and_the_exit_status_is_zero(tmp_path):
    process, report = run_verdict(tmp_path, {"Port.Send": entry(61, 62)}, strict=False)
    assert process.returncode == 0, process.stdout + process.stderr
    assert len(report["offenders"]) == 2  # over budget, and not flat
    assert "STRICT=1" in process.stdout


def test_strict_mode_fails_when_a_report_is_absent(tmp_path):
    # A step of `make bench` that wrote nothing must not pass strict mode by silence.
    process, report = run_verdict(tmp_path, {"Port.Send": entry(60, 60)}, strict=True)
    assert process.returncode == 0
    (tmp_path / "primitives.json").unlink()
    command = [sys.executable, BUDGETS_PY, "--budgets", str(tmp_path / "budgets.toml"),
               "--primitives", str(tmp_path / "primitives.json"),
               "--thread-metric", str(tmp_path / "thread_metric.json"),
               "--footprint", str(tmp_path / "footprint.json"), "--output", str(tmp_path / "out.json"), "--strict"]
    process = subprocess.run(command, capture_output=True, text=True, timeout=60)
    assert process.returncode == 1
    assert "Port.Send: no figure" in process.stderr


# A slice of a GNU ld map in the shape of build/bench/dcos486.map: an output
# section, input sections on one line and on two (a long name), a fill, the
# symbols ld lists, and merged strings listed once per object at one address.
FIXTURE_MAP = """\
Memory Configuration

Linker script and memory map

                0x00100000                . = 0x100000

.text           0x00100010      0x120
 *(.text .text.*)
 .text          0x00100010       0x40 build/fw486/firmware/runtime/src/CxxRuntime.cpp.o
                0x00100010                __cxa_pure_virtual
 .text._ZN4dcos11TaskManager4killEv
                0x00100050       0x80 build/fw486/firmware/dcos/src/task/TaskManager.cpp.o
 *fill*         0x001000d0        0x10 
 .text          0x001000e0       0x50 build/fw486/firmware/dcos/src/kernel/KernelCommands.cpp.o

.rodata         0x00101000       0x30
 .rodata.str1.1
                0x00101000       0x20 build/fw486/firmware/dcos/src/timer/TimerManager.cpp.o
 .rodata.str1.1
                0x00101000       0x18 build/fw486/drivers/can/src/Sja1000Chip.cpp.o
                                 0x30 (size before relaxing)
 .rodata        0x00101020       0x10 build/fw486/firmware/bsp_486/src/Pic8259.cpp.o

.bss            0x00102000      0x100
 .bss           0x00102000      0x100 build/fw486/firmware/dcos/src/ResourceRecovery.cpp.o

.debug_info     0x00000000      0x999
 .debug_info    0x00000000      0x999 build/fw486/firmware/dcos/src/task/TaskManager.cpp.o
"""


def test_the_footprint_report_sums_a_linker_map_by_component_and_counts_merged_strings_once():
    report = footprint.footprint(footprint.parse_map(FIXTURE_MAP), "build/fw486", ["firmware/dcos/"])
    assert report["total"] == {"text": 0x120, "rodata": 0x30, "data": 0, "bss": 0x100}
    components = report["components"]
    assert components["runtime"]["text"] == 0x40
    assert components["dcos/task"]["text"] == 0x80
    # The fill before KernelCommands' section aligns it: it counts for that object.
    assert components["dcos/commands"]["text"] == 0x10 + 0x50
    assert "alignment" not in components
    assert components["dcos/timer"]["rodata"] == 0x20
    assert components["drivers/can"]["rodata"] == 0  # its strings merged into the timer's
    assert components["bsp_486"]["rodata"] == 0x10
    assert components["dcos/shared"]["bss"] == 0x100
    assert report["kernel"] == {"text": 0x80 + 0x10 + 0x50, "rodata": 0x20, "data": 0, "bss": 0x100}
    assert report["shell_and_commands"]["text"] == 0x10 + 0x50


# The same slice for a minimal image: the kernel's core and the self-check, no shell.
MINIMAL_FIXTURE_MAP = """\
Linker script and memory map

.text           0x00100010       0x90
 .text          0x00100010       0x40 build/fw486/firmware/dcos/src/timer/TimerManager.cpp.o
 .text          0x00100050       0x30 build/fw486/firmware/selfcheck/src/SelfCheck.cpp.o
 .text          0x00100080       0x20 build/fw486/firmware/bsp_486/src/Pit8254.cpp.o

.bss            0x00102000       0x10
 .bss           0x00102000       0x10 build/fw486/firmware/dcos/src/task/TaskManager.cpp.o
"""


def test_the_footprint_report_covers_every_configurations_image_and_compares_their_kernels(tmp_path, monkeypatch,
                                                                                          capsys):
    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "full.map").write_text(FIXTURE_MAP)
    (maps / "small.map").write_text(MINIMAL_FIXTURE_MAP)
    budget_file = tmp_path / "budgets.toml"
    budget_file.write_text('[footprint.full]\nimage = "build/486/full.elf"\nkernel = ["firmware/dcos/"]\n'
                           "text_budget = 1000\n"
                           '[footprint.minimal]\nimage = "build/486/small.elf"\nkernel = ["firmware/dcos/"]\n'
                           "text_budget = 0x30\n")
    sums = {"full.elf": {"text": 0x120, "rodata": 0x30, "data": 0, "bss": 0x100},
            "small.elf": {"text": 0x90, "rodata": 0, "data": 0, "bss": 0x10}}
    monkeypatch.setattr(footprint, "image_sections", lambda image: sums[os.path.basename(image)])
    output = tmp_path / "footprint.json"
    monkeypatch.setattr(sys, "argv", ["footprint.py", "--budgets", str(budget_file), "--maps", str(maps),
                                      "--output", str(output), "--strict"])
    assert footprint.main() == 1  # the minimal kernel's 0x40 bytes of code are over its 0x30
    printed = capsys.readouterr().out
    assert "Footprint of build/486/full.elf (full)" in printed
    assert "Footprint of build/486/small.elf (minimal)" in printed
    assert re.search(r"selfcheck\s+48\s+0\s+0\s+0", printed)
    assert re.search(r"^  minimal\s+build/486/small\.elf\s+64\s+0\s+0\s+16\s+48\s+OVER$", printed, re.MULTILINE)
    assert re.search(r"^  full\s+build/486/full\.elf\s+224\s+32\s+0\s+256\s+1000\s+within$", printed, re.MULTILINE)
    report = json.loads(output.read_text())
    assert report["images"]["minimal"]["kernel"] == {"text": 0x40, "rodata": 0, "data": 0, "bss": 0x10}
    assert report["images"]["minimal"]["components"]["selfcheck"]["text"] == 0x30
    assert report["images"]["full"]["kernel"]["text"] == 0x80 + 0x10 + 0x50
    assert [row["verdict"] for row in report["budgets"]] == [budgets.WITHIN, budgets.OVER]


def test_a_measured_configuration_whose_map_is_missing_is_an_error(tmp_path, monkeypatch, capsys):
    budget_file = tmp_path / "budgets.toml"
    budget_file.write_text('[footprint.minimal]\nimage = "build/486/small.elf"\ntext_budget = 100\n')
    monkeypatch.setattr(sys, "argv", ["footprint.py", "--budgets", str(budget_file), "--maps", str(tmp_path),
                                      "--output", str(tmp_path / "footprint.json")])
    assert footprint.main() == 1
    assert "small.map" in capsys.readouterr().err


def test_padding_counts_for_the_section_it_aligns_and_only_trailing_padding_for_none():
    text = ("Linker script and memory map\n\n.text           0x00100000       0x40\n"
            " .text          0x00100000        0x8 build/fw486/firmware/boot/src/Panic.cpp.o\n"
            " *fill*         0x00100008        0x8 \n"
            " .text._ZN4dcos1fEv\n                0x00100010       0x20 build/fw486/firmware/dcos/src/task/TaskManager.cpp.o\n"
            " *fill*         0x00100030       0x10 \n")
    report = footprint.footprint(footprint.parse_map(text), "build/fw486", ["firmware/dcos/"])
    assert report["components"]["boot"]["text"] == 0x8
    assert report["components"]["dcos/task"]["text"] == 0x8 + 0x20
    assert report["components"]["alignment"]["text"] == 0x10
    assert report["total"]["text"] == 0x40


def test_components_follow_the_source_tree():
    assert footprint.component_of("firmware/dcos/src/scheduler/Scheduler.cpp") == "dcos/scheduler"
    assert footprint.component_of("firmware/dcos/src/StackArena.cpp") == "dcos/shared"
    assert footprint.component_of("firmware/dcos/src/memory/MemoryCommands.cpp") == "dcos/commands"
    assert footprint.component_of("firmware/bsp_486/src/Pit8254.cpp") == "bsp_486"
    assert footprint.component_of("firmware/shell/src/Shell.cpp") == "shell"
    assert footprint.component_of("drivers/modbus/src/LineRunner.cpp") == "drivers/modbus"
    assert footprint.component_of("fieldbus/can/src/CanFrame.cpp") == "fieldbus/can"
    assert footprint.component_of("generated/BuildRevision.cpp") == "build revision"
    assert footprint.component_of("firmware/selfcheck/src/SelfCheck.cpp") == "selfcheck"
    assert footprint.component_of("firmware/dcos/src/kernel/MinimalRoot.cpp") == "dcos/kernel"
    assert footprint.component_of(None) == "alignment"


# ---- the real budget file --------------------------------------------------------------

def registered_benchmarks():
    """Every name registered with DCOS_BENCHMARK in the bench sources."""
    names = set()
    for file_name in os.listdir(BENCH):
        if file_name.endswith(".cpp"):
            with open(os.path.join(BENCH, file_name), encoding="utf-8") as handle:
                names.update(re.findall(r'DCOS_BENCHMARK\(\s*\w+\s*,\s*"([^"]+)"', handle.read()))
    return names


def test_the_budget_file_holds_the_issues_budgets_under_registered_benchmark_names():
    real = budgets.load_budgets()
    registered = registered_benchmarks()
    assert "Kernel.ContextSwitch" in registered, "the bench sources were not found"
    for name, budget in real["primitives"].items():
        if budget["measured"]:
            assert name in registered, f"{name} has a budget but no benchmark registers that name"
        else:
            assert name not in registered, f"{name} is registered now: drop its measured = false"
        assert budget["note"], f"{name}: say in one line what the figure measures"
    expected = {"Kernel.ContextSwitch": 20, "Kernel.InterruptLatency": 30, "Kernel.StaticScheduling": 60,
                "Kernel.DynamicScheduling64": 250, "Semaphore.Acquire": 30, "Semaphore.Release": 35,
                "Port.Send": 60, "Port.Receive": 50, "Task.PostEvent": 30, "BufferPool.Allocate": 30,
                "BufferPool.Return": 30, "Dsm.Write": 60, "Dsm.Read": 50, "Timer.GetSystemClock": 60,
                "Heap.Allocate": 200, "Heap.Return": 200, "Heap.AllocateFragmented": 200}
    for name, figure in expected.items():
        assert real["primitives"][name]["budget"] == figure, name
    agents = {name.split(".")[0] for name in registered if name.endswith(".NameToObject")}
    for agent in agents:
        assert real["primitives"][f"{agent}.NameToObject"]["budget"] == 400
        assert real["primitives"][f"{agent}.NameToObject"]["flat"]
    for name in ("Timer.SetSystemClock", "Task.KillTask", "Task.Delete", "Heap.Allocate", "Heap.Return"):
        assert real["primitives"][name]["flat"], name


def test_the_remote_budgets_name_every_primitive_the_remote_bench_measures_and_ask_for_identical_calls():
    real = budgets.load_budgets()
    assert set(real["remote"]) == {name for name, _ in remote_bench.PRIMITIVES}
    for name, budget in real["remote"].items():
        assert budget["identical"], name
        assert {"caller_request", "caller_reply", "callee", "receive_interrupt_callee"} <= set(budget["figures"]), name
        assert budget["note"], f"{name}: say in one line what the transaction is"
        # Issue 14 sets no number: no budget is made up.
        assert not budget["budget"] and budget["bound"], name


def test_every_thread_metric_budget_is_half_of_freertos_and_the_footprint_budgets_are_the_issues():
    real = budgets.load_budgets()
    assert set(real["thread_metric"]) == {
        "cooperative_scheduling", "preemptive_scheduling", "interrupt_processing", "interrupt_preemption_processing",
        "message_processing", "synchronization_processing", "memory_allocation"}
    assert set(real["thread_metric"]) <= set(run_thread_metric.EXPECTED)
    for name, budget in real["thread_metric"].items():
        assert budget["budget"] == budget["freertos"] / 2, name
    assert real["footprint"]["full"]["text_budget"] == 87 * 1024 // 2
    assert real["footprint"]["minimal"]["text_budget"] == 8 * 1024
    assert real["footprint"]["full"]["image"] == "build/486/dcos486.elf"
    assert real["footprint"]["minimal"]["image"] == "build/486/dcos486-minimal.elf"
    # Both configurations are built and measured: neither budget waits for an image.
    assert real["footprint"]["full"]["measured"] and real["footprint"]["minimal"]["measured"]
