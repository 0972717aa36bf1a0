#!/usr/bin/python3
"""Runs the on-target benchmarks and reports them: what `make bench` calls.

Boots the board's bench image on its benchmark CPU model with exact
instruction counting (-icount shift=0), runs the console command
`bench run`, parses its BENCH lines (format: tests_renode/bench/BenchmarkRunner.cpp),
writes a JSON report and prints a table beside the seed's figures.

The report maps "<Agent>.<Primitive>" to
    {"instructions_8": n, "instructions_4096": n, "variable": bool, "cost": "constant" | "log" | "variable"}
where n is the smallest instruction count of one call with that many
objects (null when setup failed). See docs/performance.md.
"""

import argparse
import json
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # tests_renode, for dcoslab
sys.path.insert(0, HERE)

from dcoslab.board import REPOSITORY, load_board  # noqa: E402
from dcoslab.emulator import Emulator, EmulatorError  # noqa: E402
from seed_figures import SEED_PROCESSOR, seed_text  # noqa: E402

OBJECT_COUNTS = (8, 4096)
PROMPT = r"dcos> "

RESULT_LINE = re.compile(
    r"^BENCH (?P<name>\S+) objects=(?P<objects>\d+) min=(?P<min>\d+) max=(?P<max>\d+) "
    r"variable=(?P<variable>[01]) cost=(?P<cost>constant|log|variable)\r?$",
    re.MULTILINE,
)
ERROR_LINE = re.compile(r"^BENCH (?P<name>\S+) objects=(?P<objects>\d+) error=(?P<code>\d+) (?P<text>.*?)\r?$",
                        re.MULTILINE)
OVERHEAD_LINE = re.compile(r"^BENCH overhead min=(?P<min>\d+) max=(?P<max>\d+) warmup=(?P<warmup>\d+) "
                           r"repeat=(?P<repeat>\d+)\r?$", re.MULTILINE)
LIST_LINE = re.compile(r"^BENCH (?P<name>\S+) cost=(?P<cost>constant|log|variable) variable=(?P<variable>[01]) "
                       r"irq=(?P<irq>on|off)\r?$", re.MULTILINE)


class BenchmarkError(Exception):
    pass


def parse_run(output):
    """Parses the output of `bench run` into (overhead, {name: entry})."""
    overhead = OVERHEAD_LINE.search(output)
    if overhead is None:
        raise BenchmarkError("no 'BENCH overhead' line in the output of 'bench run'")
    results = {}
    for match in RESULT_LINE.finditer(output):
        entry = results.setdefault(match["name"], {"cost": match["cost"], "variable": match["variable"] == "1"})
        entry[int(match["objects"])] = (int(match["min"]), int(match["max"]))
    for match in ERROR_LINE.finditer(output):
        entry = results.setdefault(match["name"], {"cost": "?", "variable": False})
        entry[int(match["objects"])] = f"setup failed: {match['text']}"
    return {key: int(value) for key, value in overhead.groupdict().items()}, results


def run_on_target(board, image, selection, repeat, timeout):
    """Boots the bench image and returns the output of `bench run` and the emulator's argv."""
    emulator = Emulator(board, image, icount=True, cpu=board.benchmark_cpu or None)
    try:
        emulator.start(timeout=timeout)
        emulator.expect(PROMPT, timeout=timeout)
        line = "bench run" + (f" {selection}" if selection else "") + (f" --repeat {repeat}" if repeat else "")
        output = emulator.command(line, timeout=timeout)
        if not re.search(r"^BENCH done\r?$", output, re.MULTILINE):
            raise BenchmarkError(f"'{line}' did not end with 'BENCH done':\n"
                                 f"----- console transcript -----\n{emulator.transcript}\n"
                                 "----- end of transcript -----")
        return output, emulator.argv
    finally:
        emulator.close()


def report_entry(entry):
    def smallest(objects):
        value = entry.get(objects)
        return value[0] if isinstance(value, tuple) else None

    return {
        "instructions_8": smallest(8),
        "instructions_4096": smallest(4096),
        "variable": entry["variable"],
        "cost": entry["cost"],
    }


def count_text(value):
    if value is None:
        return "-"
    if isinstance(value, str):
        return "failed"
    low, high = value
    return str(low) if low == high else f"{low}..{high}"


def order_check(entry):
    """flat / NOT FLAT for O(1) primitives; the declared order otherwise."""
    if entry["cost"] == "log":
        return "O(log n)"
    if entry["cost"] == "variable":
        return "-"
    small, large = entry.get(8), entry.get(4096)
    if not isinstance(small, tuple) or not isinstance(large, tuple):
        return "?"
    # The figures are the minimums (the maximum of a benchmark that runs with
    # interrupts enabled may include an interrupt handler).
    return "flat" if small[0] == large[0] else "NOT FLAT"


def print_table(results, overhead, cpu):
    print(f"DCOS kernel benchmarks: bench image on -cpu {cpu}, -icount shift=0 (rdtsc = retired instructions)")
    print(f"figures: instructions retired by one call beyond an empty call (timing overhead {overhead['min']} "
          f"subtracted), smallest of {overhead['repeat']} after {overhead['warmup']} warm-up calls; "
          "a..b where the largest differs")
    print()
    headers = ("benchmark", "8 objects", "4096 objects", "O(1) check", "variable", "seed (P-150)")
    rows = []
    for name in sorted(results):
        entry = results[name]
        rows.append((name, count_text(entry.get(8)), count_text(entry.get(4096)), order_check(entry),
                     "variable" if entry["variable"] else "", seed_text(name) or "-"))
    widths = [max(len(str(row[i])) for row in rows + [headers]) for i in range(len(headers))]
    aligns = ("<", ">", ">", "<", "<", "<")
    for row in [headers] + rows:
        print("  ".join(f"{cell:{align}{width}}" for cell, align, width in zip(row, aligns, widths)).rstrip())
    print()
    for name in sorted(results):
        for objects in OBJECT_COUNTS:
            if isinstance(results[name].get(objects), str):
                print(f"{name} with {objects} objects: {results[name][objects]}")
    not_flat = [row[0] for row in rows if row[3] == "NOT FLAT"]
    if not_flat:
        print(f"NOT FLAT: {', '.join(not_flat)} declared O(1) but cost differs between 8 and 4096 objects")
    matched = sum(1 for row in rows if row[5] != "-")
    print(f"seed figures (Tables 9.2-9.11, microseconds on a {SEED_PROCESSOR}, end to end through the trap "
          f"interface) shown for {matched} of {len(rows)} benchmarks; they are not instruction counts")
    print("KVM cycle figures: not reported yet. Only exact instruction counts under QEMU TCG with -icount are "
          "measured; real-time cycle counts under KVM (medians) are future work.")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--board", default="isa486")
    parser.add_argument("--image", help="bench image (default: the board's 'benchmark' image)")
    parser.add_argument("--output", default=os.path.join(REPOSITORY, "build", "bench", "kernel.json"),
                        help="JSON report to write")
    parser.add_argument("--select", default="", help="one benchmark or one agent, e.g. Timer or Kernel.ResolveId")
    parser.add_argument("--repeat", type=int, default=0, help="measured calls per object count (default: target's)")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds for each wait on the emulator")
    parser.add_argument("--strict", action="store_true", help="exit 1 when an O(1) benchmark is NOT FLAT")
    arguments = parser.parse_args()

    board = load_board(arguments.board)
    if not board.benchmark_cpu:
        print(f"board {board.name} names no benchmark_cpu; the bench image needs a CPU with rdtsc", file=sys.stderr)
        return 2
    image = arguments.image or board.image("benchmark")
    try:
        output, argv = run_on_target(board, image, arguments.select, arguments.repeat, arguments.timeout)
        overhead, results = parse_run(output)
    except (EmulatorError, BenchmarkError) as error:
        print(f"make bench: the benchmark run failed.\n{error}", file=sys.stderr)
        return 1
    if not results:
        print(f"make bench: 'bench run' reported no benchmarks:\n{output}", file=sys.stderr)
        return 1
    missing = [name for name, entry in results.items() if any(objects not in entry for objects in OBJECT_COUNTS)]
    if missing:
        print(f"make bench: no figures for every object count from {', '.join(missing)}:\n{output}", file=sys.stderr)
        return 1

    print("emulator: " + " ".join(argv))
    print_table(results, overhead, board.benchmark_cpu)

    os.makedirs(os.path.dirname(os.path.abspath(arguments.output)), exist_ok=True)
    with open(arguments.output, "w", encoding="utf-8") as handle:
        json.dump({name: report_entry(results[name]) for name in sorted(results)}, handle, indent=2)
        handle.write("\n")
    print(f"wrote {arguments.output}")
    if arguments.strict and any(order_check(entry) == "NOT FLAT" for entry in results.values()):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
