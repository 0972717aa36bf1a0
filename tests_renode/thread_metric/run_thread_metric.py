#!/usr/bin/env python3
"""Runs the Thread-Metric suite on the bench image and records instructions per iteration.

The bench image runs on the board's benchmark CPU (a Pentium model) under
-icount, where the time-stamp counter counts retired instructions, so every
figure is exact and the same on every run and every machine. Writes
build/bench/thread_metric.json as {"<test>": {"iterations": n,
"instructions": n, "instructions_per_iteration": x, "budget": null | {...}}, ...}
and prints a table, each test beside its budget in
tests_renode/bench/budgets.toml (at most half of FreeRTOS's figure) where it
has one. --strict exits 1 when a test is over its budget; `make bench`
leaves that verdict to tests_renode/bench/budgets.py.
"""

import argparse
import json
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bench"))

from dcoslab.board import load_board  # noqa: E402
from dcoslab.emulator import Emulator  # noqa: E402
import budgets as budget_file  # noqa: E402

LINE = re.compile(r"TM (\w+) iterations=(\d+) instructions=(\d+) per_iteration=([\d.]+)")
EXPECTED = [
    "basic_processing",
    "cooperative_scheduling",
    "preemptive_scheduling",
    "interrupt_processing",
    "interrupt_preemption_processing",
    "message_processing",
    "synchronization_processing",
    "memory_allocation",
]


def run(board_name):
    board = load_board(board_name)
    emulator = Emulator(board, board.image("benchmark"), icount=True, cpu=board.benchmark_cpu,
                        memory_mib=board.benchmark_memory())
    try:
        emulator.start()
        emulator.expect(r"dcos> ")
        emulator.send("threadmetric\r")
        emulator.expect(r"TM done", timeout=600)
        results = {}
        for name, iterations, instructions, per_iteration in LINE.findall(emulator.transcript):
            results[name] = {
                "iterations": int(iterations),
                "instructions": int(instructions),
                "instructions_per_iteration": float(per_iteration),
            }
        missing = [name for name in EXPECTED if name not in results]
        if missing:
            raise SystemExit(f"Thread-Metric tests did not report: {', '.join(missing)}\n{emulator.transcript}")
        return results
    finally:
        emulator.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--board", default="isa486")
    parser.add_argument("--output", default="build/bench/thread_metric.json")
    parser.add_argument("--budgets", default=budget_file.DEFAULT_BUDGETS, help="the budget file (budgets.toml)")
    parser.add_argument("--strict", action="store_true", help="exit 1 when a test is over its budget")
    arguments = parser.parse_args()
    budgets = budget_file.load_budgets_for_command(arguments.budgets)
    if budgets is None:
        return 2
    results = run(arguments.board)
    rows = budget_file.check_thread_metric(budgets, results)
    for entry in results.values():
        entry["budget"] = None
    for row in rows:
        if row["name"] in results:
            results[row["name"]]["budget"] = {key: row[key] for key in ("budget", "freertos", "now", "verdict",
                                                                       "offences")}
    os.makedirs(os.path.dirname(arguments.output), exist_ok=True)
    with open(arguments.output, "w", encoding="utf-8") as handle:
        json.dump(results, handle, indent=2, sort_keys=True)
    print("Thread-Metric, instructions per iteration (exact: retired instructions under -icount)")
    print(f"{'test':36} {'iterations':>10} {'per iteration':>14}")
    for name in EXPECTED:
        entry = results[name]
        print(f"{name:36} {entry['iterations']:>10} {entry['instructions_per_iteration']:>14.2f}")
    print("\n".join(budget_file.thread_metric_lines(rows)))
    print(f"written to {arguments.output}")
    found = budget_file.offenders(rows)
    if arguments.strict and found:
        print(f"run_thread_metric.py --strict: {len(found)} offenders:", file=sys.stderr)
        for offence in found:
            print(f"  {offence}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
