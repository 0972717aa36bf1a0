#!/usr/bin/env python3
"""The bench's remote transaction figures (docs/performance.md, "Remote transactions").

Two emulated 486 boards (test image, -icount) on the lab's CAN bus at
1 Mbit/s, node 1 and node 2, each with channel 0 attached to the network
interfaces manager (docs/guide/remote-objects.md). Node 1 calls each
carried primitive on node 2's objects through the `remote` console command
and reports:

- the round trip, from the call to its return on node 1, in microseconds of
  emulated time (the board's uptime), beside the seed's network latency of
  80 us, one way (dissertation, 9.3.4 and Table 9.11), so 160 us a round trip;
- the frames each call put on the bus, from the hub's log;
- for publications (docs/protocols/publications.md), on two buses: the
  frames per publication on each bus, the bus time one publication takes
  (its first frame's start to its third frame's end), and the pages a
  remote subscriber took, missed, saw twice or torn.

The figures are measurements, not budgets: the round trip is mostly the two
frames' bit times at 1 Mbit/s, which no code change shortens.
"""

import argparse
import json
import os
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # tests_renode, for dcoslab

from dcoslab.board import REPOSITORY, load_board  # noqa: E402
from dcoslab.canlab import CanLab  # noqa: E402
from dcoslab.emulator import EmulatorError  # noqa: E402
from dcoslab.remote import (REPLY, REQUEST, attach_redundant, call, created, dcos_frames,  # noqa: E402
                            publication_records, publish, subscribe, wait_tally)
from dcoslab.vmworld import World  # noqa: E402

BIT_RATE = 1_000_000
SEED_LATENCY_US = 80  # network latency, one way: dissertation 9.3.4, Table 9.11


def frame_counts(lab):
    """How many remote requests and replies the hub's log holds so far."""
    return len(dcos_frames(lab, REQUEST)), len(dcos_frames(lab, REPLY))


def measure(lab, caller, calls, calls_per_primitive):
    """Each (name, command) run calls_per_primitive times: its status, round trips and frames per call."""
    results = {}
    for name, command in calls:
        before = frame_counts(lab)
        trips, statuses = [], set()
        for _ in range(calls_per_primitive):
            status, _, microseconds = call(caller, command)
            statuses.add(status)
            trips.append(microseconds)
        after = frame_counts(lab)
        results[name] = {
            "status": sorted(statuses),
            "round_trip_us": {"min": min(trips), "median": statistics.median(trips), "max": max(trips)},
            "request_frames_per_call": (after[0] - before[0]) / calls_per_primitive,
            "reply_frames_per_call": (after[1] - before[1]) / calls_per_primitive,
        }
    return results


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
    arguments = parser.parse_args()
    calls_per_primitive = arguments.calls

    world = World()
    try:
        world.lab = CanLab(world.boot, load_board("isa486"), {"can0": BIT_RATE, "can1": BIT_RATE},
                           {"node1": {"bus0": "can0", "bus1": "can1", "append": "node=1"},
                            "node2": {"bus0": "can0", "bus1": "can1", "append": "node=2"}}, kind="test",
                           timeout=arguments.timeout)
        caller, server = world.lab.board("node1"), world.lab.board("node2")
        # Both channels attached; remote transactions go over can0 (mapped first).
        attach_redundant(caller, 1, [2], BIT_RATE, arguments.timeout)
        attach_redundant(server, 2, [1], BIT_RATE, arguments.timeout)
        semaphore = created(server, "remote sem 1000000", "RSEM")
        listener = created(server, "remote listener", "RTASK")
        port = created(server, "remote port", "RPORT")
        results = measure(world.lab, caller, [
            ("SemaphoreGetCount", f"count {semaphore}"),
            ("SemaphoreAcquire (no wait)", f"acquire {semaphore} 0"),
            ("SemaphoreRelease", f"release {semaphore}"),
            ("PostEvent", f"post {listener} 0x1"),
            # Sixteen bytes at priority 5: a request of three frames.
            ("MessagePortSend", f"send {port} {5 * 256 + 1}"),
        ], calls_per_primitive)
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
    counts = publications["subscriber"]
    print(f"Publications of one global publisher, {publications['writes']} Writes, on can0 and can1: the remote "
          f"subscriber took {counts['received']}, missed {counts['gaps']}, saw {counts['repeats']} twice, "
          f"{counts['torn']} torn")
    for bus, entry in publications["buses"].items():
        span = entry["bus_time_us"]
        print(f"  {bus}: {entry['frames_per_publication']:.1f} frames per publication, "
              f"{span['min']:.0f} / {span['median']:.0f} / {span['max']:.0f} us on the bus (min/median/max)")
    report = {"bit_rate": BIT_RATE, "calls_per_primitive": calls_per_primitive,
              "seed_latency_us": SEED_LATENCY_US, "primitives": results, "publications": publications}
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
