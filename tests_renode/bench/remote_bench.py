#!/usr/bin/env python3
"""The bench's remote transaction figures (docs/performance.md, "Remote transactions").

Two emulated 486 boards (the counting test image on the board's benchmark
CPU, -icount) on the lab's CAN bus at 1 Mbit/s, node 1 and node 2, each with channel 0 attached to the network
interfaces manager (docs/guide/remote-objects.md). Node 1 calls each
carried primitive on node 2's objects through the `remote` console command
and reports:

- the round trip, from the call to its return on node 1, in microseconds of
  emulated time (the board's uptime), beside the seed's network latency of
  80 us, one way (dissertation, 9.3.4 and Table 9.11), so 160 us a round trip;
- the frames each call put on the bus, from the hub's log;
- the instructions each call costs on each node, exactly: the boards run the
  counting test image (build/486/dcos486-test-counting.elf) on the board's
  benchmark CPU (-cpu pentium -icount shift=0), whose time-stamp counter
  counts retired instructions, and the remote agent keeps the counts of the
  last transaction on each side (`net remote`): on the caller, its own work
  (the request handed to the link, and the reply from its receive interrupt
  to the return) apart from its whole span, the wait for the bus included;
  on the callee, from the request's receive interrupt to the reply handed
  to the link; and, on both, the CAN driver's receive interrupt routine
  for one frame on its own (`can stats`);
- for publications (docs/protocols/publications.md), on two buses: the
  frames per publication on each bus, the bus time one publication takes
  (its first frame's start to its third frame's end), and the pages a
  remote subscriber took, missed, saw twice or torn.

The round trips are measurements, not budgets: they are mostly the two
frames' bit times at 1 Mbit/s, which no code change shortens. The
instruction counts are held against the [remote] budgets of budgets.toml
(budgets.py).
"""

import argparse
import json
import os
import re
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # tests_renode, for dcoslab

from dcoslab.board import REPOSITORY, load_board  # noqa: E402
from dcoslab.canlab import CanLab  # noqa: E402
from dcoslab.emulator import EmulatorError  # noqa: E402
from dcoslab.remote import (REPLY, REQUEST, attach_redundant, call, created, dcos_frames,  # noqa: E402
                            net_counters, publication_records, publish, subscribe, wait_tally)
from dcoslab.vmworld import World  # noqa: E402
import budgets as budget_file  # noqa: E402

BIT_RATE = 1_000_000
SEED_LATENCY_US = 80  # network latency, one way: dissertation 9.3.4, Table 9.11
# The test image with the instruction counter (mk/bench.mk), on the CPU whose
# time-stamp counter -icount turns into an exact instruction count.
IMAGE_KIND = "test-counting"
# The primitives measured, by name, and the `remote` command that calls each
# on node 2's objects (filled in with their ids).
PRIMITIVES = (
    ("SemaphoreGetCount", "count {semaphore}"),
    ("SemaphoreAcquire (no wait)", "acquire {semaphore} 0"),
    ("SemaphoreRelease", "release {semaphore}"),
    ("PostEvent", "post {listener} 0x1"),
    # Sixteen bytes at priority 5: a request of three frames.
    ("MessagePortSend", f"send {{port}} {5 * 256 + 1}"),
)
# The callers' priority: more urgent than the test image's listener (10) and
# porter (9) on the serving node, less than the remote agent's receiver (0).
CALL_PRIORITY = 8

# The per-call instruction figures of a primitive, as remote.json names them:
# (name, what it is).
INSTRUCTION_FIGURES = (
    ("caller_request", "caller: from the remote agent's start of the transaction to its request handed to the link"),
    ("caller_reply", "caller: from the receive interrupt of the reply to the return to the primitive"),
    ("caller_own", "caller: its own work, caller_request + caller_reply"),
    ("caller_span", "caller: from the same start to the same return, the halted wait for the bus included"),
    ("caller_waiting", "caller: caller_span - caller_own, the wait (the processor halted, and the interrupts that "
                       "come meanwhile)"),
    ("callee", "callee: from the receive interrupt of the request's last frame to the reply handed to the link, "
               "with callee_parts_before"),
    ("callee_parts_before", "callee: of callee, the earlier frames of a request of several (interrupt and "
                            "receiver each)"),
)


def frame_counts(lab):
    """How many remote requests and replies the hub's log holds so far."""
    return len(dcos_frames(lab, REQUEST)), len(dcos_frames(lab, REPLY))


def reply_gaps(records):
    """Per reply in the hub's records, ns from the end of the request frame before it to the reply's start.

    The serving node's share of a transaction, from the interrupt of the
    request's last frame to the reply handed to its chip, is nearly this
    interval (one instruction per ns): its count starts after the kernel's
    interrupt entry and ends a few dozen instructions after the chip began
    the reply. The two agreeing shows that no halt hides in the count."""
    gaps, last_request = [], None
    for record in records:
        raw = record.frame.id
        if record.outcome != "ok" or not record.frame.extended:
            continue
        kind = (raw >> 16) & 0xFF
        if kind == REQUEST:
            last_request = record
        elif kind == REPLY and last_request is not None:
            gaps.append(record.start - last_request.end)
            last_request = None
    return gaps


def spread(values):
    """min, median and max of a list of numbers."""
    return {"min": min(values), "median": statistics.median(values), "max": max(values)}


def receive_interrupt_instructions(board):
    """The CAN driver's count of its last receive interrupt routine for one frame (`can stats can0`)."""
    output = board.command("can stats can0")
    match = re.search(r"receive_interrupt_instructions=(\d+)", output)
    assert match, output
    return int(match.group(1))


def call_instructions(caller, server):
    """The remote agent's counts of the last transaction, on the caller and on the callee (`net remote`)."""
    mine, theirs = net_counters(caller), net_counters(server)
    if "call-span-instructions" not in mine or "serve-instructions" not in theirs:
        raise AssertionError("the boards count no instructions: is this the counting image on a CPU with a "
                             f"time-stamp counter?\n{caller.command('net remote')}")
    own = mine["call-request-instructions"] + mine["call-reply-instructions"]
    return {"caller_request": mine["call-request-instructions"], "caller_reply": mine["call-reply-instructions"],
            "caller_own": own, "caller_span": mine["call-span-instructions"],
            "caller_waiting": mine["call-span-instructions"] - own,
            "callee": theirs["serve-instructions"], "callee_parts_before": theirs["serve-parts-instructions"]}


def measure(lab, caller, server, calls, calls_per_primitive):
    """Each (name, command) run calls_per_primitive times: its status, round trips, frames and instructions per call.

    A command is a `remote` primitive (tests_renode/target/
    RemoteTransactionsTest.cpp) with its verb first. Each is called just
    after a tick ("tick"), so that no tick interrupt lands in a call on
    either node; at priority CALL_PRIORITY, which the serving worker
    inherits, so that the test image's listener and porter tasks, which a
    PostEvent or a Send readies, run after the reply rather than inside the
    callee's count; and once unmeasured first: the first transaction of a
    kind takes paths the next ones do not (a worker's first change of
    priority, a sender's first entry in the table of requests being put
    together)."""
    results = {}
    for name, command in calls:
        verb, _, rest = command.partition(" ")
        command = f"{verb} at={CALL_PRIORITY} tick {rest}"
        call(caller, command)
        before = frame_counts(lab)
        records_before = len(lab.hub.frames())
        trips, statuses, counts = [], set(), []
        for _ in range(calls_per_primitive):
            status, _, microseconds = call(caller, command)
            statuses.add(status)
            trips.append(microseconds)
            counts.append(call_instructions(caller, server))
        after = frame_counts(lab)
        gaps = reply_gaps(lab.hub.frames()[records_before:])
        instructions = {figure: spread([count[figure] for count in counts]) for figure, _ in INSTRUCTION_FIGURES}
        instructions["per_call"] = counts
        # The last call's frames: the reply on the caller, the request's last frame on the callee.
        instructions["receive_interrupt_caller"] = receive_interrupt_instructions(caller)
        instructions["receive_interrupt_callee"] = receive_interrupt_instructions(server)
        results[name] = {
            "status": sorted(statuses),
            "round_trip_us": spread(trips),
            "request_frames_per_call": (after[0] - before[0]) / calls_per_primitive,
            "reply_frames_per_call": (after[1] - before[1]) / calls_per_primitive,
            "bus_gap_ns": spread(gaps) if gaps else None,
            "instructions": instructions,
        }
    return results


def count_text(figure):
    """A spread of counts as "min" or "min..max"."""
    return f"{figure['min']}" if figure["min"] == figure["max"] else f"{figure['min']}..{figure['max']}"


def measure_publications(lab, writer, reader, writes, timeout):
    """writes Writes of a global publisher on writer, read on reader: frames, bus time, what the reader saw."""
    publisher = publish(writer, "bench", priority=10, period_ms=5, count=writes, timeout=timeout)
    subscribe(reader, publisher, priority=5, timeout=timeout)
    wait_tally(lab, reader, lambda status, _: status != "busy", "the subscription", timeout)
    writer.command("pubsub go", timeout=timeout)
    status, counts = wait_tally(lab, reader, lambda _, c: c["last"] == writes, f"page {writes}", timeout)
    lab.hub.wait_until(lab.hub.now_ns + 5_000_000, timeout)
    buses = {}
    for bus in ("can0", "can1"):
        records = publication_records(lab, bus)
        spans = [records[i + 2].end - records[i].start for i in range(0, len(records) - 2, 3)]
        buses[bus] = {"frames_per_publication": len(records) / writes,
                      "bus_time_us": {"min": min(spans) / 1000, "median": statistics.median(spans) / 1000,
                                      "max": max(spans) / 1000}}
    return {"status": status, "writes": writes, "subscriber": counts, "buses": buses}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", default=os.path.join(REPOSITORY, "build", "bench", "remote.json"))
    parser.add_argument("--calls", type=int, default=20, help="calls per primitive")
    parser.add_argument("--writes", type=int, default=50, help="Writes of the published page")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds for each wait on the emulators")
    parser.add_argument("--budgets", default=budget_file.DEFAULT_BUDGETS,
                        help="the budget file whose [remote] budgets the instruction counts are held against")
    arguments = parser.parse_args()
    calls_per_primitive = arguments.calls
    budgets = budget_file.load_budgets_for_command(arguments.budgets)
    if budgets is None:
        return 2

    world = World()
    board = load_board("isa486")
    try:
        world.lab = CanLab(world.boot, board, {"can0": BIT_RATE, "can1": BIT_RATE},
                           {"node1": {"bus0": "can0", "bus1": "can1", "append": "node=1"},
                            "node2": {"bus0": "can0", "bus1": "can1", "append": "node=2"}}, kind=IMAGE_KIND,
                           timeout=arguments.timeout, cpu=board.benchmark_cpu)
        caller, server = world.lab.board("node1"), world.lab.board("node2")
        # Both channels attached; remote transactions go over can0 (mapped first).
        attach_redundant(caller, 1, [2], BIT_RATE, arguments.timeout)
        attach_redundant(server, 2, [1], BIT_RATE, arguments.timeout)
        semaphore = created(server, "remote sem 1000000", "RSEM")
        listener = created(server, "remote listener", "RTASK")
        port = created(server, "remote port", "RPORT")
        objects = {"semaphore": semaphore, "listener": listener, "port": port}
        results = measure(world.lab, caller, server,
                          [(name, command.format(**objects)) for name, command in PRIMITIVES], calls_per_primitive)
        publications = measure_publications(world.lab, server, caller, arguments.writes, arguments.timeout)
    except (EmulatorError, AssertionError) as error:
        print(f"remote_bench.py: the run failed.\n{error}", file=sys.stderr)
        return 1
    finally:
        world.close()

    print(f"Remote transactions between two boards on CAN at {BIT_RATE // 1000} kbit/s "
          f"({calls_per_primitive} calls each; emulated time, -icount)")
    print(f"  {'primitive':28} {'status':8} {'round trip us (min/median/max)':>32} {'frames/call':>12}")
    for name, entry in results.items():
        trip = entry["round_trip_us"]
        frames = entry["request_frames_per_call"] + entry["reply_frames_per_call"]
        print(f"  {name:28} {','.join(entry['status']):8} "
              f"{trip['min']:>12} / {trip['median']:>7} / {trip['max']:>7} {frames:>12.1f}")
    print(f"  the seed's network latency (9.3.4, Table 9.11): {SEED_LATENCY_US} us one way, "
          f"{2 * SEED_LATENCY_US} us a round trip")
    print(f"Instructions per remote transaction ({calls_per_primitive} calls each; exact: -cpu "
          f"{board.benchmark_cpu} -icount shift=0; min, or min..max where the calls differ)")
    print(f"  {'primitive':28} {'caller: request + reply = own':>31} {'span':>15} {'callee':>9} "
          f"{'rx interrupt (caller/callee)':>29}")
    for name, entry in results.items():
        counts = entry["instructions"]
        own = f"{count_text(counts['caller_request'])} + {count_text(counts['caller_reply'])} = " \
              f"{count_text(counts['caller_own'])}"
        interrupts = f"{counts['receive_interrupt_caller']} / {counts['receive_interrupt_callee']}"
        print(f"  {name:28} {own:>31} {count_text(counts['caller_span']):>15} {count_text(counts['callee']):>9} "
              f"{interrupts:>29}")
    print("  span: the caller's whole call, the halted wait for the bus included (one count per ns under -icount); "
          "callee: request's receive interrupt to the reply on the link")
    rows = budget_file.check_remote(budgets, results)
    for line in budget_file.remote_lines(rows, arguments.budgets):
        print(line)
    counts = publications["subscriber"]
    print(f"Publications of one global publisher, {publications['writes']} Writes, on can0 and can1: the remote "
          f"subscriber took {counts['received']}, missed {counts['gaps']}, saw {counts['repeats']} twice, "
          f"{counts['torn']} torn")
    for bus, entry in publications["buses"].items():
        span = entry["bus_time_us"]
        print(f"  {bus}: {entry['frames_per_publication']:.1f} frames per publication, "
              f"{span['min']:.0f} / {span['median']:.0f} / {span['max']:.0f} us on the bus (min/median/max)")
    for name, entry in results.items():
        entry["budgets"] = [row for row in rows if row["primitive"] == name]
    report = {"bit_rate": BIT_RATE, "calls_per_primitive": calls_per_primitive,
              "seed_latency_us": SEED_LATENCY_US, "cpu": board.benchmark_cpu, "image": board.images[IMAGE_KIND],
              "instruction_figures": dict(INSTRUCTION_FIGURES), "primitives": results,
              "publications": publications}
    os.makedirs(os.path.dirname(os.path.abspath(arguments.output)), exist_ok=True)
    with open(arguments.output, "w", encoding="utf-8") as handle:
        json.dump(report, handle, indent=2)
        handle.write("\n")
    print(f"wrote {arguments.output}")
    bad = [name for name, entry in results.items() if entry["status"] != ["ok"]]
    if publications["status"] != "ok" or counts["received"] != publications["writes"] or counts["repeats"] \
            or counts["torn"]:
        bad.append("publications")
    if bad:
        print(f"remote_bench.py: calls that did not succeed: {', '.join(bad)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
