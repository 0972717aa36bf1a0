#!/usr/bin/env python3
"""The dual-Pentium board's figures (docs/performance.md, "The dual-Pentium board").

One dual-Pentium board (tests_renode/boards/p5smp.json, the test image, both processors, -icount): node 2 on
the first processor, node 3 on the second, joined by the shared-memory network
(docs/protocols/shared-memory.md). It reports:

- the round trip of each primitive the remote agent carries, called on the other node of the same board,
  in both directions, beside the same call on the caller's own object: microseconds of emulated time from
  the call to its return (the caller's uptime, as the `remote` console command of the test image measures
  it); a pool's Allocate and Return among them, which only nodes that share memory carry
  (docs/protocols/remote-transactions.md, "Pools and heaps");
- the latency of the inter-processor interrupt that carries each message: from the sender's stamp of the
  time-stamp counter, just before it raises the other processor's line 2, to the receiving node's routine
  (`shm`), in emulated nanoseconds.

Under -icount QEMU runs both processors on one host thread, round robin, and a processor runs until its
time slice ends or it halts: an interrupt sent to the other processor is taken when that one next runs.
The latency therefore says how the emulator schedules its two processors as much as how the board's
APICs deliver; on the real board it is the APIC bus's few microseconds. The figures are measurements, not
budgets (the single-node tables of run_benchmarks.py are the isa486 board's; the kernel is the same).
"""

import argparse
import os
import re
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # tests_renode, for dcoslab

from dcoslab.board import REPOSITORY, load_board  # noqa: E402
from dcoslab.emulator import Emulator, EmulatorError  # noqa: E402
from dcoslab.node_console import NodeConsole  # noqa: E402
from dcoslab.remote import call, created  # noqa: E402
from run_benchmarks import write_json  # noqa: E402


IMAGE_KIND = "test"
# The primitives measured, by name, and the `remote` command that calls each on the served node's objects.
PRIMITIVES = (
    ("SemaphoreGetCount", "count {semaphore}"),
    ("SemaphoreAcquire (no wait)", "acquire {semaphore} 0"),
    ("SemaphoreRelease", "release {semaphore}"),
    ("PostEvent", "post {listener} 0x1"),
    ("MessagePortSend", "send {port} " + str(5 * 256 + 1)),
)
# Allocate and Return of a pool's buffer, measured in pairs (the test image's pool holds eight buffers).
POOL_PRIMITIVES = ("BufferPoolAllocate", "BufferPoolReturn")
# The callers' priority: more urgent than the test image's listener (10) and porter (9), less than the
# remote agent's receiver (0), as in remote_bench.py.
CALL_PRIORITY = 8


def objects_on(console):
    """A semaphore (never exhausted), the listener task and the porter's port, created on one node."""
    return {"semaphore": created(console, "remote sem 1000000", "RSEM"),
            "listener": created(console, "remote listener", "RTASK"),
            "port": created(console, "remote port", "RPORT"),
            "pool": created(console, "remote pool", "RPOOL")}


def spread(values):
    return {"min": min(values), "median": statistics.median(values), "max": max(values)}


def round_trips(caller, objects, calls):
    """Per primitive: the statuses seen and the round trip in us (min/median/max) of calls calls."""
    results = {}
    for name, command in PRIMITIVES:
        verb, rest = command.format(**objects).split(" ", 1)
        line = f"{verb} at={CALL_PRIORITY} {rest}"
        measured = [call(caller, line) for _ in range(calls)]
        results[name] = {"status": sorted({status for status, _, _ in measured}),
                         "round_trip_us": spread([us for _, _, us in measured])}
    allocated, returned = [], []
    for _ in range(calls):
        allocated.append(call(caller, f"alloc at={CALL_PRIORITY} {objects['pool']}"))
        returned.append(call(caller, f"free at={CALL_PRIORITY} {objects['pool']} {allocated[-1][1]}"))
    for name, measured in zip(POOL_PRIMITIVES, (allocated, returned)):
        results[name] = {"status": sorted({status for status, _, _ in measured}),
                         "round_trip_us": spread([us for _, _, us in measured])}
    return results


def shm_counts(console, node):
    output = console.command("shm")
    match = re.search(rf"shm node {node} to node \d+: (.*)", output)
    if not match:
        raise AssertionError(f"node {node}'s shm answered: {output!r}")
    return {key: int(value) for key, value in re.findall(r"(\w+)=(\d+)", match.group(1))}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", default=os.path.join(REPOSITORY, "build", "bench", "p5smp.json"))
    parser.add_argument("--calls", type=int, default=20, help="calls per primitive and direction")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds for each wait on the emulator")
    arguments = parser.parse_args()

    board = load_board("p5smp")
    emulator = Emulator(board, board.image(IMAGE_KIND), icount=True, serial_sockets=("node3",))
    node3 = None
    try:
        emulator.start()
        emulator.expect(r"dcos> ", timeout=arguments.timeout)
        node3 = NodeConsole(emulator, "node3")
        node3.prompt(timeout=arguments.timeout)
        on2, on3 = objects_on(emulator), objects_on(node3)
        directions = {
            "node 3 on node 2's objects": round_trips(node3, on2, arguments.calls),
            "node 2 on node 3's objects": round_trips(emulator, on3, arguments.calls),
            "node 2 on its own objects": round_trips(emulator, on2, arguments.calls),
        }
        interrupts = {"node 2 (from node 3)": shm_counts(emulator, 2), "node 3 (from node 2)": shm_counts(node3, 3)}
    except (EmulatorError, AssertionError) as error:
        print(f"p5smp_bench.py: the run failed.\n{error}", file=sys.stderr)
        return 1
    finally:
        if node3 is not None:
            node3.close()
        emulator.close()

    print(f"The dual-Pentium board: primitives on the other node of the board over shared memory "
          f"({arguments.calls} calls each; emulated time, -icount, both processors)")
    print(f"  {'primitive':28} " + "".join(f"{direction:>30}" for direction in directions))
    for name in [name for name, _ in PRIMITIVES] + list(POOL_PRIMITIVES):
        cells = []
        for direction in directions.values():
            trip = direction[name]["round_trip_us"]
            cells.append(f"{','.join(direction[name]['status'])} {trip['min']}/{trip['median']:g}/{trip['max']} us")
        print(f"  {name:28} " + "".join(f"{cell:>30}" for cell in cells))
    print("  round trip min/median/max, from the call to its return on the caller")
    print("Inter-processor interrupt latency, the sender's stamp to the receiver's routine (emulated ns):")
    for receiver, counts in interrupts.items():
        print(f"  {receiver:22} {counts['interrupts']:>6} interrupts, least {counts['latency_min']} ns, "
              f"most {counts['latency_max']} ns, last {counts['latency_last']} ns")
    print("  under -icount the other processor takes an interrupt when the emulator next runs it (see above)")
    report = {"board": board.name, "image": board.images[IMAGE_KIND], "calls_per_primitive": arguments.calls,
              "call_priority": CALL_PRIORITY, "round_trips": directions, "interrupts": interrupts}
    write_json(arguments.output, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
