#!/usr/bin/env python3
"""Runs the Thread-Metric suite on the bench image and records instructions per iteration.

The bench image runs on the board's benchmark CPU (a Pentium model) under
-icount, where the time-stamp counter counts retired instructions, so every
figure is exact and the same on every run and every machine. Writes
build/bench/thread_metric.json as {"<test>": {"iterations": n,
"instructions": n, "instructions_per_iteration": x}, ...} and prints a table.
"""

import argparse
import json
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from dcoslab.board import load_board  # noqa: E402
from dcoslab.emulator import Emulator  # noqa: E402

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
    arguments = parser.parse_args()
    results = run(arguments.board)
    os.makedirs(os.path.dirname(arguments.output), exist_ok=True)
    with open(arguments.output, "w", encoding="utf-8") as handle:
        json.dump(results, handle, indent=2, sort_keys=True)
    print("Thread-Metric, instructions per iteration (exact: retired instructions under -icount)")
    print(f"{'test':36} {'iterations':>10} {'per iteration':>14}")
    for name in EXPECTED:
        entry = results[name]
        print(f"{name:36} {entry['iterations']:>10} {entry['instructions_per_iteration']:>14.2f}")
    print(f"written to {arguments.output}")


if __name__ == "__main__":
    main()
